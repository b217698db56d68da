"""Layer 5, analyses on top of the solver: the operating point and the resonance map
(modes), the linearisation, and parameter sweeps on Dask."""
