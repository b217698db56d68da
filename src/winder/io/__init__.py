"""Layer 0, input and output: result objects and their files (CSV, NPZ with units),
atomic writes, interrupts (SIGINT/SIGTERM/SIGHUP) and progress bars."""
