"""Layer 5, the FMU: building a co-simulation FMU of a scene, its slave, and the FMPy host
the command line uses."""
