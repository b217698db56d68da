"""The generic result channels of a machine (machines.md §9), declared once: time, every
body's rotation and free coordinates, every nip's forces, every web's speed. A part's
own channels are on its body element (``CHANNELS``: a paper roll's radius, mass, ...),
an effect's on its force element (``CHANNELS``). The run-time inputs a body takes
(:attr:`~winder.parts.BodyElement.torque_inputs`, ``setpoint_inputs``) are declared here
too, with their units (:data:`INPUTS`): the FMU's inputs carry them."""

from __future__ import annotations

from winder._schema import Channel

__all__ = ["TIME", "BODY_CHANNELS", "COORD_CHANNELS", "NIP_CHANNELS", "WEB_SPEED",
           "GENERIC_CHANNELS", "TORQUE_INPUT", "SETPOINT_INPUT", "INPUTS", "input_of"]

#: The first column of every result.
TIME = Channel(name="t", unit="s", doc="time")

#: Every body's rotation, in the order the machine writes them.
BODY_CHANNELS = (
    Channel(name="BODY_speed", unit="rad/s", doc="speed in the body's operation sense (s θ̇)",
            whole="drive"),
    Channel(name="BODY_angle", unit="rad", doc="angle in the operation sense (s θ)",
            whole="drive"),
    Channel(name="BODY_torque", unit="N·m",
            doc="driven body: its drive torque (inverse dynamics for a speed profile, the "
                "input or the controller's torque otherwise); undriven body: the torque of "
                "the nip friction and web forces about its axis; operation sense, without "
                "gravity, imbalance and −Ẏv", whole="drive_sum"),
    Channel(name="BODY_accel", unit="rad/s²",
            doc="angular acceleration in the operation sense", whole="drive"),
)

#: A free coordinate's channels by coordinate (``x``, ``z``): position, rate, acceleration.
COORD_CHANNELS = {
    "x": (Channel(name="BODY_x", unit="m", doc="centre x, for a body free along x",
                  whole="mean"),
          Channel(name="BODY_x_dot", unit="m/s", doc="ẋ", whole="mean"),
          Channel(name="BODY_x_accel", unit="m/s²", doc="ẍ", whole="mean")),
    "z": (Channel(name="BODY_z", unit="m", doc="centre z, for a body free along z",
                  whole="mean"),
          Channel(name="BODY_z_dot", unit="m/s", doc="ż", whole="mean"),
          Channel(name="BODY_z_accel", unit="m/s²", doc="z̈", whole="mean")),
}

#: Every nip's channels.
NIP_CHANNELS = (
    Channel(name="NIP_normal_force", unit="N", doc="normal force F_n (0: open)"),
    Channel(name="NIP_friction_force", unit="N", doc="friction force F_t, on b along +t"),
    Channel(name="NIP_slip_velocity", unit="m/s", doc="slip v_s = u_a − u_b"),
    Channel(name="NIP_penetration", unit="m",
            doc="penetration δ = r_a + r_b − |c_b − c_a| (negative: open)"),
)

#: Every web's speed (``WEB_web_speed`` with several webs).
WEB_SPEED = Channel(name="web_speed", unit="m/s",
                    doc="surface speed of the drum at the entry nip")

#: The generic channels, in the reference's order.
GENERIC_CHANNELS = (TIME, *BODY_CHANNELS, *COORD_CHANNELS["x"], *COORD_CHANNELS["z"],
                    *NIP_CHANNELS, WEB_SPEED)

#: A torque-driven body's drive torque, the run-time parameter ``BODY.torque``
#: (:attr:`~winder.parts.BodyElement.torque_inputs`; the FMU input ``BODY_torque``).
TORQUE_INPUT = Channel(name="BODY_torque", unit="N·m", doc="drive torque")
#: A tension-controlled unwind's set-point, the run-time parameter
#: ``ROLL.tension_setpoint`` (:attr:`~winder.parts.BodyElement.setpoint_inputs`).
SETPOINT_INPUT = Channel(name="ROLL_tension_setpoint", unit="N", doc="tension set-point")
#: Every kind of run-time input, by the run-time parameter's name after the body's.
INPUTS = (TORQUE_INPUT, SETPOINT_INPUT)


def input_of(parameter: str) -> Channel:
    """The declaration of the run-time input ``parameter`` (``front.torque``:
    :data:`TORQUE_INPUT`); KeyError for a parameter that is no input."""
    suffix = parameter.rpartition(".")[2]
    for decl in INPUTS:
        if decl.suffix == suffix:
            return decl
    raise KeyError(parameter)
