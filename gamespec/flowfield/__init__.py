"""Pursuit-evasion in stochastic flow fields (chapter 5): the kind (:mod:`.spec`) and the numerics.

The flow field (:mod:`.field`), forward reachability by level sets on a grid (:mod:`.grid`,
:mod:`.upwind`, :mod:`.tvd_rk`, :mod:`.hamiltonian`, :mod:`.band`, :mod:`.scratch`,
:mod:`.levelset`, :mod:`.capture`) and by extremal shooting (:mod:`.extremals`), the nominal
trajectories (:mod:`.nominal`), their linearization and zero-order hold (:mod:`.linearize`), the
covariance game (:mod:`.covariance_game`), the capture probability (:mod:`.capture_probability`)
and the Monte Carlo of the SDE (:mod:`.simulation`); the two stages' specs and the Result that joins
them (:mod:`.stages`). No solver is imported here.
"""
