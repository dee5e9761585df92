"""Dynamical systems of the engine (the lead reconciles the System interface here)."""
