"""The hexapod's struts as built (planbench.hexapod.physics.STRUT_DRIVE): the model's drive-train
elements against their definitions, the start in static equilibrium through the screws'
compliance, and the counting encoders."""

from __future__ import annotations

import math

import numpy as np
import pytest

from planbench import hexapod as sim_hexapod
from planbench import runner, scenarios
from planbench.drives import transmission_stiffness
from planbench.hexapod import physics as hexapod_physics
from planbench.planners.hexapod import STRUT_LABELS

DRIVE = hexapod_physics.STRUT_DRIVE


@pytest.fixture(scope="module")
def as_built():
    return hexapod_physics.HexapodPhysics.load(45.0, drives="as-built")


def test_each_strut_has_its_motor_screw_friction_and_loops(as_built):
    model = as_built.model.ptr
    # N = 2 pi x 10 (gearbox) / 10 mm (lead); the rotor reflected: J N^2 = 4e-4 x 6283^2 = 15 791 kg.
    assert DRIVE.ratio == pytest.approx(2 * math.pi * 10 / 0.010)
    assert DRIVE.reflected_inertia == pytest.approx(4e-4 * (2 * math.pi * 10 / 0.010) ** 2)
    # The position loop: 20 Hz, zeta 0.7 against the rotor and a 1 t share of the payload.
    m = DRIVE.reflected_inertia + 1000.0
    assert DRIVE.kp == pytest.approx(m * (2 * math.pi * 20) ** 2)
    assert DRIVE.kv == pytest.approx(2 * 0.7 * m * 2 * math.pi * 20)
    # K_t I N eta: 0.9 N m/A x 10.13 A x 6283 rad/m x 0.873 = 50 kN (8.10 A: 40 kN).
    assert DRIVE.torque_constant * DRIVE.peak_current * DRIVE.ratio * 0.97 * 0.9 == pytest.approx(50e3)
    assert DRIVE.peak_force == pytest.approx(50e3) and DRIVE.continuous_force == pytest.approx(40e3)
    for name in STRUT_LABELS:
        motor, rod = model.joint(f"{name}_motor"), model.joint(name)
        assert model.dof_armature[motor.dofadr[0]] == pytest.approx(DRIVE.reflected_inertia)
        assert model.dof_armature[rod.dofadr[0]] == 0.0
        assert model.dof_frictionloss[motor.dofadr[0]] == DRIVE.coulomb_friction
        assert model.dof_damping[motor.dofadr[0]] == DRIVE.viscous_friction
        tendon = model.tendon(f"{name}_transmission").id
        assert model.tendon_stiffness[tendon] == DRIVE.stiffness
        actuator = model.actuator(name)
        assert actuator.trnid[0] == motor.id
        np.testing.assert_allclose(actuator.forcerange, [-50e3, 50e3])
        for axis in ("u1", "u2"):
            assert model.jnt_stiffness[model.joint(f"{name}_{axis}").id] == hexapod_physics.FLEXURE_STIFFNESS


@pytest.mark.parametrize("elevation", [15.0, 90.0])
def test_the_start_is_static_equilibrium_through_the_screws(elevation):
    """Each motor stands off its rod by F / k (the static strut load over the screw's
    stiffness), and with the drives holding the reference controller's start the struts stay
    put: under 0.05 um in 0.25 s."""
    scenario = scenarios.get("hexapod-sync-move")
    setup = scenario.build(scenario.resolve(elevation=elevation, wind=0.0, duration=0.25))
    physics = setup.physics
    q = physics.data.qpos[physics.strut_qpos].copy()
    force = hexapod_physics.static_drive_forces(physics, q[None])[0]
    np.testing.assert_allclose(physics.data.qpos[physics.drive_qpos] - q, force / DRIVE.stiffness, rtol=1e-12)
    assert np.abs(force).max() > 5e3  # a real load: 7.8 kN at 90 deg, 38 kN at 15 deg
    log = runner.simulate(setup)
    drift = log.qpos[:, physics.strut_qpos] - q
    assert np.abs(drift).max() < 0.05e-6 + np.abs(log.reference.position - log.reference.position[0]).max()


def test_the_controller_reads_whole_encoder_counts():
    scenario = scenarios.get("hexapod-sync-move")
    setup = scenario.build(scenario.resolve(wind=0.0, duration=0.5))
    spec = next(s for s in setup.task.sensors.specs if s.name == "joint_positions")
    assert spec.resolution == DRIVE.encoder_resolution == 50e-9
    readings = []

    class Recorder(sim_hexapod.HexapodController):
        def __call__(self, tick, observation):
            readings.append(observation["joint_positions"].copy())
            super().__call__(tick, observation)

    setup.components.controller = Recorder()
    log = runner.simulate(setup)
    counts = np.array(readings) / 50e-9
    np.testing.assert_allclose(counts, np.round(counts), atol=1e-6)
    truth = log.qpos[: len(readings), setup.physics.strut_qpos]
    assert np.all((truth - np.array(readings) >= -1e-15) & (truth - np.array(readings) < 50e-9 * (1 + 1e-9)))


def test_the_ideal_drives_are_the_mjcf_as_it_is():
    ideal = hexapod_physics.HexapodPhysics.load(45.0, drives="ideal")
    model = ideal.model.ptr
    assert model.nu == 6 and model.ntendon == 6 and model.njnt == 19  # 6 x (u1, u2, slide) + the platform
    assert all(np.isinf(transmission_stiffness(model, n)) for n in STRUT_LABELS)
    np.testing.assert_array_equal(ideal.drive_qpos, ideal.strut_qpos)


def test_an_unknown_drive_option_is_refused_naming_the_choices():
    with pytest.raises(ValueError, match=r"drives = 'geared' is not one of as-built, ideal"):
        scenarios.get("hexapod-sync-move").resolve(drives="geared")


@pytest.mark.parametrize(
    "field, value, expect",
    [
        (
            "friction_error",
            0.5,
            lambda m, n: (m.dof_frictionloss[m.joint(f"{n}_motor").dofadr[0]], 1.5 * DRIVE.coulomb_friction),
        ),
        (
            "friction_error",
            -0.5,
            lambda m, n: (m.dof_damping[m.joint(f"{n}_motor").dofadr[0]], 0.5 * DRIVE.viscous_friction),
        ),
        (
            "screw_stiffness_error",
            -0.3,
            lambda m, n: (m.tendon_stiffness[m.tendon(f"{n}_transmission").id], 0.7 * DRIVE.stiffness),
        ),
        ("torque_constant_error", 0.1, lambda m, n: (m.actuator(n).gainprm[0], 1.1 * DRIVE.kp)),
        ("torque_constant_error", 0.1, lambda m, n: (-m.actuator(n).biasprm[2], 1.1 * DRIVE.kv)),
        ("torque_constant_error", -0.1, lambda m, n: (m.actuator(n).forcerange[1], 0.9 * DRIVE.peak_force)),
    ],
)
def test_the_drive_trains_uncertainty_edits_its_element(field, value, expect):
    plant = sim_hexapod.HexapodPlant(**{field: value})
    model = hexapod_physics.HexapodPhysics.load(45.0, plant, "as-built").model.ptr
    for name in STRUT_LABELS:
        actual, wanted = expect(model, name)
        assert actual == pytest.approx(wanted, rel=1e-12)
    # and nothing else of the drive: the other elements keep the nominal values
    nominal = hexapod_physics.HexapodPhysics.load(45.0, drives="as-built").model.ptr
    assert model.nv == nominal.nv and model.ntendon == nominal.ntendon
