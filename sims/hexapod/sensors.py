"""The hexapod's sensors: the six strut encoders (``sensors``)."""

from __future__ import annotations

import dataclasses

from planbench.hexapod.params import CONTROL_DT
from planbench.hexapod.physics import STRUT_DRIVE, HexapodPhysics
from planbench.task import JointEncoders


def sensors(physics: HexapodPhysics) -> JointEncoders:
    """The hexapod's sensors: the six strut encoders (length change from the zero pose),
    every tick, with the plant's encoder bias (``physics.encoder_bias``) if it has one; with the
    as-built drives they count in steps of the linear encoder's resolution
    (``STRUT_DRIVE.encoder_resolution``), with the ideal ones they read exactly."""
    bias = physics.encoder_bias
    encoders = JointEncoders(
        physics.strut_qpos,
        physics.strut_dofs,
        physics.strut_act,
        "strut encoders (length change from the zero pose)",
        "m",
        CONTROL_DT,
        bias=0.0 if bias is None else bias,
        resolution=STRUT_DRIVE.encoder_resolution if physics.drives == "as-built" else 0.0,
    )
    if bias is not None and bias.any():
        # The datasheet a controller is given (ControlContext.sensors) cannot state the true
        # zero offset of this machine's encoders: it is the plant's (summary.json's "plant").
        encoders.specs[0] = dataclasses.replace(encoders.specs[0], bias="unknown zero offset (plant uncertainty)")
    return encoders
