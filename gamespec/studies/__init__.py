"""Studies built from load → solve → Result: backend comparisons, sweeps, Monte Carlo."""
