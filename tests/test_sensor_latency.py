"""Every reading reaches the controller no earlier than its datasheet latency, at its rate.

For every scenario a recording controller wraps the reference controller and keeps, each
tick, a copy of the observation and of the true state (``qpos``, ``qvel``, ``act``: the test
reads the physics, the wrapped controller does not). Then for every ``SensorSpec`` of the
``ControlContext`` (rate_hz, latency_s):

* a sensor whose readings carry their sample time (``<stem>_time``, the spec's name or its
  prefix; ``<stem>_count`` the readings delivered) is at least ``latency_s`` old at every tick
  once its first reading arrived, and at most latency + one period + one tick (the freshest
  delivered), and its stamps step by 1 / rate_hz;
* a sensor without stamps must have latency 0 (one with a latency and no stamp could not be
  judged); a noise-free one must read the true state of the same tick (each component equals
  a column of qpos, qvel or act), so a reading delayed by a tick fails too.

Kills FAST's total stations and GPS/RTK delivering with zero latency while their specs say
0.2 / 0.04 s (the RTK's 50 ms on the 20 ms grid), and any sensor that reads the present
while its spec says otherwise.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from planbench import runner, scenarios

RUNS = {  # the shortest runs that see several readings of the slowest sensor (s)
    "loader-supply": 0.5,
    "loader-direct": 0.5,
    "hexapod-sync-move": 0.5,
    "hexapod-async-move": 0.5,
    "antenna-paper-motion": 1.0,
    "antenna-sea-state": 1.0,
    "fast-tracking": 2.0,
    "fast-ra-scan": 2.0,
    "fast-source-switch": 2.0,
}


class Recording:
    """The reference controller, and a copy of each tick's observation and true state."""

    def __init__(self, inner, physics):
        self.inner, self.physics = inner, physics
        self.readings, self.truth, self.ticks = [], [], []

    def reset(self, context):
        self.context = context
        return self.inner.reset(context)

    def __call__(self, tick, observation):
        self.ticks.append(tick)
        self.readings.append({k: np.array(v, dtype=float, copy=True) for k, v in observation.items()})
        d = self.physics.data
        self.truth.append(np.concatenate([d.qpos, d.qvel, d.act]).copy())
        return self.inner(tick, observation)


def recorded(name: str) -> Recording:
    spec = scenarios.get(name)
    setup = spec.build(spec.resolve({"duration": RUNS[name]}))
    recording = Recording(setup.components.controller, setup.physics)
    runner.simulate(dataclasses.replace(setup, components=dataclasses.replace(setup.components, controller=recording)))
    return recording


def stamp_of(sensor: str, keys) -> str | None:
    """The stem of the ``<stem>_time`` key that stamps ``sensor``'s readings, or None."""
    stems = [k[:-5] for k in keys if k.endswith("_time")]
    stems = [s for s in stems if sensor == s or sensor.startswith(s + "_")]
    return max(stems, key=len) if stems else None


def test_every_scenario_is_covered():
    assert set(RUNS) == set(scenarios._registry()[0])


@pytest.mark.parametrize("name", sorted(RUNS))
def test_readings_are_no_newer_than_their_latency(name):
    rec = recorded(name)
    dt = rec.context.control_dt
    physics_dt = rec.context.model.opt.timestep
    t = np.asarray(rec.ticks) * dt
    keys = rec.readings[0].keys()
    truth = np.array(rec.truth)
    judged = []
    for sensor in rec.context.sensors:
        stem = stamp_of(sensor.name, keys)
        period = 1.0 / sensor.rate_hz
        if stem is not None:
            stamp = np.array([r[f"{stem}_time"][0] for r in rec.readings])
            count = (
                np.array([r[f"{stem}_count"][0] for r in rec.readings])
                if f"{stem}_count" in keys
                else np.ones_like(stamp)
            )
            seen = count > 0
            assert seen.sum() >= 3, (sensor.name, "fewer than 3 ticks with a reading")
            age = t[seen] - stamp[seen]
            worst = int(np.argmin(age))
            assert age.min() >= sensor.latency_s - 1e-9, (
                f"{name}: {sensor.name} read at t = {t[seen][worst]:.3f} s is {age[worst] * 1e3:.1f} ms old, "
                f"its spec says a latency of {sensor.latency_s * 1e3:.1f} ms"
            )
            assert age.max() <= sensor.latency_s + period + dt + 1e-9, (name, sensor.name, age.max())
            steps = np.diff(np.unique(stamp[seen]))
            if steps.size:
                # A stamp is when MuJoCo's sensors saw the state: the t = 0 sample at t = 0, the
                # later ones at the start of their tick's last physics step (planbench.antenna.AntennaImu),
                # so the first interval may be one physics step short, and no other.
                first = steps[0] if stamp[seen][0] == 0.0 else period
                assert period - physics_dt - 1e-9 <= first <= period + 1e-9, (name, sensor.name, first)
                np.testing.assert_allclose(steps[1:], period, atol=1e-9, err_msg=f"{name}: {sensor.name}'s rate")
            judged.append(sensor.name)
            continue
        assert sensor.latency_s == 0.0, f"{name}: {sensor.name} has a latency but its readings no time stamp"
        assert sensor.rate_hz == pytest.approx(1.0 / dt), (name, sensor.name, "read every tick")
        if sensor.noise != "none":
            continue  # its noise hides the true state; its latency is 0 and it is read every tick
        values = np.array([r[sensor.name] for r in rec.readings]).reshape(len(rec.readings), -1)
        for j in range(values.shape[1]):
            column = values[:, j]
            scale = max(1e-12, float(np.abs(column).max()))
            # A counting encoder reads the truth to within one count (floor(x / r) r).
            same = np.abs(truth - column[:, None]).max(axis=0) <= max(1e-9 * scale, sensor.resolution)
            assert same.any(), f"{name}: {sensor.name}[{j}] is not the true state of the same tick"
        judged.append(sensor.name)
    assert judged, name
