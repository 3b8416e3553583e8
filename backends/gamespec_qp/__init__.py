"""qpsolvers backend plugin (ProxSuite's proxqp by default; any installed qpsolvers solver by name)."""
