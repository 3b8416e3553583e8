"""The ``analytic`` backend plugin: exact constant-bearing optima and the eq. 2.27 heading."""
