"""Layer 5, the FMU: the native FMI 2.0 FMU of a scene (co-simulation and model exchange,
the compiled machine behind it, no Python inside), its parameters, and the FMPy host the
command line checks it with."""
