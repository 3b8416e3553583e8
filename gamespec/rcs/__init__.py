"""Constraint-desensitized planning (thesis §6.4): relevant constraint sensitivity, moving obstacles."""
