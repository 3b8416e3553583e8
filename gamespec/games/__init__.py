"""Game drivers above the solving chain: differential games whose players are compiled as
``optimal_control`` problems (chapter 7)."""
