"""Layer 4, solving: the :class:`~winder.solve.system.MachineSystem` (generated code,
modes, parameters), the compiled integrators (DOPRI5, RK4, ROS2) with located events, the
static balance of the initial state, the budgets, and the one driver shared by
:func:`~winder.solve.simulate.simulate` and the :class:`~winder.solve.stepper.Stepper`."""
