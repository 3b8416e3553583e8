"""Problem kinds: the shared base models and one module per kind (registered by entry point)."""
