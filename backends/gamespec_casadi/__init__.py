"""CasADi backend of gamespec: direct collocation solved by the IPOPT inside the CasADi wheel."""
