"""The model room: what a design is, before anything is computed.

Holds the dimensionless parameters of Eq. (9) (``params``), their short aliases (``aliases``),
the backlash laws and their registry (``backlash``), the commensurability of the excitation
frequencies (``frequencies``), the conversion of physical gear data (``conversion``) and the
documented examples (``examples``). Imports only pydantic, numpy and its own modules: every
other room of the engine builds on this one.
"""
