"""Backend-neutral machinery for ``optimal_control`` specs: the symbolic model, the collocation
grid, translation of SymPy into each backend's expressions, initial guesses and the checks that
every backend's Result gets, computed independently of the solver."""
