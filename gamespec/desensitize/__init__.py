"""Desensitized optimal control (chapter 6): sensitivity functions, Seywald's sensitivity matrix,
co-state desensitization (C-DOC), and the Monte Carlo re-simulation that checks them."""
