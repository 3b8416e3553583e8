"""Games built from solves: the best-response engine (:mod:`gamespec.games.best_response`)."""
