"""The ship-borne 4-axis satellite antenna in MuJoCo: ship motion, the IMU-driven planner
controller, checks and scenarios.

Scenarios:
  antenna-paper-motion  the paper's section 5.1: satellite at Az 223.49, El 60, pol -28.8 deg,
                        ship motion of eq. (15)-(16) (pitch 40 deg / 8 s, roll 45 deg / 10 s,
                        1 deg/s turn), 60 s
  antenna-sea-state     a ship at 40 N 20 W holding a geostationary satellite at 15 W in a
                        JONSWAP sea (Hs 5 m, Tp 10 s, waves 135 deg off the bow; ``--hs``,
                        ``--tp``, ``--heading``), 300 s

The ship's motion drives the deck through stiff servo drives with inverse-dynamics
feed-forward (``ShipMotionDrive``, the sea: not part of the controller), so the antenna feels
the real base accelerations. The controller (``AntennaController``) sees only what a real one
sees: the IMU on the pedestal base (orientation and gyro), sampled at 20-50 Hz with noise and
latency. Per IMU sample it predicts the deck attitude to the end of the next update interval
from the gyro (rate and its change), forms N = bTe eTs (paper, eq. 1), runs one planner update
(CRR, paper section 4.2) and ramps the servo set-points to the new joint angles, with the
servo's velocity feed-forward.

Modules:
  params      the scenarios' parameters (``AntennaParams``, ``AntennaPaperParams``,
              ``AntennaSeaParams``), the IMU's datasheet (``ImuModel``), the plant's
              uncertainty (``AntennaPlant``) and their constants
  physics     ``AntennaPhysics``, the dm_control Physics of models/antenna/scene.xml
  sensors     ``AntennaImu``, the pedestal IMU and the antenna's encoders
  controller  ``AntennaController``, the reference controller
  task        the sea (``ShipMotionDrive``), the evaluation, ``build``, ``plan``, the
              scenarios and the environment reward
  ship_motion the paper's ship motion and the JONSWAP sea through the ship's RAOs
  report, bench  the run's plots, ``planbench bench``'s planner rows
"""

from __future__ import annotations

from planbench.antenna.controller import AntennaController
from planbench.antenna.params import (
    CONTROL_DT,
    DECK_JOINTS,
    DRIVES,
    IMU_ATTITUDE_NOISE_DEG,
    IMU_ATTITUDE_NOISE_TIME_S,
    IMU_GYRO_NOISE_DEG_S,
    IMU_LATENCY_MAX_S,
    IMU_LATENCY_S,
    IMU_RATE_HZ,
    IMU_RATE_MIN_HZ,
    JOINTS,
    MAST_JOINTS,
    MAX_SAILED_M,
    MIN_SATELLITE_ELEVATION_DEG,
    MOVING_BODIES,
    PAPER_DURATION_S,
    REFERENCE_DT,
    SATELLITE_LON_DEG,
    SEA_DURATION_S,
    SEA_HEADING_DEG,
    SEA_HS_M,
    SEA_TP_S,
    SHIP_LAT_DEG,
    SHIP_LON_DEG,
    AntennaPaperParams,
    AntennaParams,
    AntennaPlant,
    AntennaSeaParams,
    ImuModel,
    log_bytes_per_tick,
    satellite_of,
)
from planbench.antenna.physics import AntennaPhysics
from planbench.antenna.sensors import AntennaImu
from planbench.antenna.task import (
    ATTITUDE_FRO_LIMIT,
    POINTING_MAX_PAPER_DEG,
    POINTING_MAX_SEA_DEG,
    POINTING_RMS_DEG,
    POLARIZATION_MAX_DEG,
    SCENARIOS,
    AntennaEvaluation,
    AntennaOptions,
    ShipMotionDrive,
    ShipMotionTrajectory,
    build,
    compare_methods,
    environment_reward,
    ideal_path,
    joint_kinds,
    motion_of,
    plan,
    pointing_errors,
    start_angles,
    tracked_start,
    write_method_comparison,
)
from planbench.scenarios import Mechanism

MECHANISM = Mechanism("antenna", SCENARIOS, environment_reward, benchmark_runs=5)

__all__ = [
    "ATTITUDE_FRO_LIMIT",
    "AntennaController",
    "AntennaEvaluation",
    "AntennaImu",
    "AntennaOptions",
    "AntennaPaperParams",
    "AntennaParams",
    "AntennaPhysics",
    "AntennaPlant",
    "AntennaSeaParams",
    "CONTROL_DT",
    "DECK_JOINTS",
    "DRIVES",
    "IMU_ATTITUDE_NOISE_DEG",
    "IMU_ATTITUDE_NOISE_TIME_S",
    "IMU_GYRO_NOISE_DEG_S",
    "IMU_LATENCY_MAX_S",
    "IMU_LATENCY_S",
    "IMU_RATE_HZ",
    "IMU_RATE_MIN_HZ",
    "ImuModel",
    "JOINTS",
    "MAST_JOINTS",
    "MAX_SAILED_M",
    "MECHANISM",
    "MIN_SATELLITE_ELEVATION_DEG",
    "MOVING_BODIES",
    "PAPER_DURATION_S",
    "POINTING_MAX_PAPER_DEG",
    "POINTING_MAX_SEA_DEG",
    "POINTING_RMS_DEG",
    "POLARIZATION_MAX_DEG",
    "REFERENCE_DT",
    "SATELLITE_LON_DEG",
    "SCENARIOS",
    "SEA_DURATION_S",
    "SEA_HEADING_DEG",
    "SEA_HS_M",
    "SEA_TP_S",
    "SHIP_LAT_DEG",
    "SHIP_LON_DEG",
    "ShipMotionDrive",
    "ShipMotionTrajectory",
    "build",
    "compare_methods",
    "environment_reward",
    "ideal_path",
    "joint_kinds",
    "log_bytes_per_tick",
    "motion_of",
    "plan",
    "pointing_errors",
    "satellite_of",
    "start_angles",
    "tracked_start",
    "write_method_comparison",
]
