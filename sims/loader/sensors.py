"""The loader's sensors: the drives' encoders on theta1 ... theta6."""

from __future__ import annotations

import dataclasses

import numpy as np

from planbench import models
from planbench.loader.params import CONTROL_DT
from planbench.loader.physics import LoaderPhysics, joint_drive
from planbench.task import JointEncoders


def sensors(physics: LoaderPhysics, bias=None) -> JointEncoders:
    """The loader's sensors: the drives' encoders on theta1 ... theta6, every tick. With the
    drives as built they are the motors' encoders (the arm has no joint-side ones, as an
    industrial arm's): each reads its motor's angle over the transmission ratio, in counts of
    2 pi / (2^20 N) (``planbench.loader.physics.MOTOR_ENCODER_COUNTS``), so it does not see the
    reducer's deflection or backlash; with the ideal drives they read the joints exactly.
    ``bias`` (6,) m and rad: the plant's encoder zero offsets (``LoaderPlant.encoder_bias``),
    added to every reading; None or zeros: none."""
    model = physics.model.ptr
    ideal = physics.drives == "ideal"
    resolution = (
        0.0 if ideal else [joint_drive(models.load("loader"), n).encoder_resolution for n in physics.joint_names]
    )
    measures = (
        "encoders of theta1 (m) ... theta6 (rad)"
        if ideal
        else "motor encoders of theta1 (m) ... theta6 (rad), read through the transmission ratios"
    )
    encoders = JointEncoders(
        physics.drive_qpos,
        physics.drive_dofs,
        [model.actuator(n).actadr[0] for n in physics.joint_names],
        measures,
        "m|rad",
        CONTROL_DT,
        bias=0.0 if bias is None else bias,
        resolution=resolution,
    )
    if bias is not None and np.any(bias):
        # The datasheet a controller is given (ControlContext.sensors) cannot state the true
        # zero offset of this machine's encoders: it is the plant's (summary.json's "plant").
        encoders.specs[0] = dataclasses.replace(encoders.specs[0], bias="unknown zero offset (plant uncertainty)")
    return encoders
