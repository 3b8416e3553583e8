"""Pyomo backend of gamespec: the same direct collocation as the CasADi backend, written as a Pyomo
model and solved through AMPL NL files by ``ripopt`` (bundled with pyomo-ripopt) or ``ipopt``."""
