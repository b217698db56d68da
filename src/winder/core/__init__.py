"""The core of the generated Pinocchio/CasADi model (issue 14)."""
