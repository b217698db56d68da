"""Layer 1, the model: the math namespace (numbers or CasADi symbols), Pinocchio's
algorithms on it (route "cpp" :mod:`~winder.model.pin_casadi`, route "py"
:mod:`~winder.model.spatial`), the paper roll's mass law, the variable-mass body of the
Pinocchio extension, the :class:`~winder.model.machine.Machine` that assembles the body and
force elements of a scene into one ``pin.Model`` and evaluates its dynamics once, and the
code generator that compiles that evaluation to C. Imports nothing above it (no parts,
forces or scene)."""
