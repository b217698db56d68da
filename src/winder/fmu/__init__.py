"""Layer 5, the FMU: the native FMU of a scene, FMI 2.0 or 3.0 (co-simulation and model
exchange, the compiled machine behind it, no Python inside), its variables, parameters and
model description, and the FMPy host the command line checks it with."""
