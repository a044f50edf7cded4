"""The loader's sensors: the drives' encoders on theta1 ... theta6."""

from __future__ import annotations

import dataclasses

import numpy as np

from sims.loader.params import CONTROL_DT
from sims.loader.physics import LoaderPhysics
from sims.task import JointEncoders


def sensors(physics: LoaderPhysics, bias=None) -> JointEncoders:
    """The loader's sensors: the drives' encoders on theta1 ... theta6, exact, every tick
    (no encoder figures are published for it; an assumption, README.md). ``bias`` (6,) m and
    rad: the plant's encoder zero offsets (``LoaderPlant.encoder_bias``), added to every
    reading; None or zeros: none."""
    model = physics.model.ptr
    joints = [model.joint(n) for n in physics.joint_names]
    encoders = JointEncoders([j.qposadr[0] for j in joints], [j.dofadr[0] for j in joints],
                             [model.actuator(n).actadr[0] for n in physics.joint_names],
                             "encoders of theta1 (m) ... theta6 (rad)", "m|rad", CONTROL_DT,
                             bias=0.0 if bias is None else bias)
    if bias is not None and np.any(bias):
        # The datasheet a controller is given (ControlContext.sensors) cannot state the true
        # zero offset of this machine's encoders: it is the plant's (summary.json's "plant").
        encoders.specs[0] = dataclasses.replace(encoders.specs[0], bias="unknown zero offset (plant uncertainty)")
    return encoders
