"""Planner-only checks of hexapod runs (planbench.hexapod.plan_checks): against a run's own checks,
against sampling every tick, bad plans, batches against single runs, random moves."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from planbench import api, scenarios
from planbench.hexapod import HexapodMove, HexapodParams, pose_mm_deg, pose_si, problems
from planbench.hexapod.plan_checks import judge_plans, judge_trajectories
from planbench.params import ParamError
from planbench.planners import hexapod as hp
from planbench.planners.trajectory import TrajectorySample

#: The checks that judge a limit the paper's generator keeps by construction.
KEPT = (
    "arrival_spread",
    "arrival_vs_own_time",
    "strut_velocity",
    "strut_accel",
    "plan_stroke",
    "plan_pose_error_final",
)


def by_name(checks):
    return {c.name: c for c in checks}


def random_params(rng, n, moves_per_run=1):
    """``n`` runs of ``moves_per_run`` moves each, start and targets uniform inside the pose
    limits and the stroke, the modes alternating."""
    out = []
    for i in range(n):
        poses = hp.random_poses(moves_per_run + 1, rng)
        moves = tuple(HexapodMove(pose_mm_deg(p), bool((i + k) % 2 == 0)) for k, p in enumerate(poses[1:]))
        out.append(HexapodParams(start_pose=pose_mm_deg(poses[0]), moves=moves))
    return out


# ----------------------------------------------------------------------------- against a run


@pytest.mark.parametrize("name", ["hexapod-sync-move", "hexapod-async-move"])
def test_agrees_with_the_runs_own_planner_checks(name):
    scenario = scenarios.get(name)
    run = by_name(api.run(name).checks)
    [judged] = judge_plans([scenario.params])
    plan = by_name(judged)
    assert all(c.passed for c in judged), [c for c in judged if not c.passed]
    # Quantities of the reference the run's checks take from the planned trajectory.
    arrival = "arrival_spread" if scenario.params.moves[0].synchronous else "arrival_vs_own_time"
    for key in (arrival, "strut_velocity", "strut_accel"):
        assert plan[key].value == pytest.approx(run[key].value, rel=1e-12, abs=1e-15), key
        assert (plan[key].limit, plan[key].unit, plan[key].comparison) == (
            run[key].limit,
            run[key].unit,
            run[key].comparison,
        )
    # The run's stroke is the encoders': the plan's within the run's following error.
    following_mm = 1e-3 * run["following_error"].value
    assert plan["plan_stroke"].value == pytest.approx(run["stroke"].value, abs=following_mm)
    assert plan["plan_stroke"].limit == run["stroke"].limit
    assert plan["plan_pose_error_final"].limit == run["pose_error_final"].limit
    assert plan["plan_pose_error_final"].value < 1e-6  # um: the planned end is the target


# ----------------------------------------------------------------------------- against every tick


def test_fast_path_equals_sampling_every_tick():
    """The paper's plans judged from their switching ticks equal the same plans sampled at
    every control tick (judge_trajectories via a planner given explicitly); the pose along the
    path, continuous in the fast path, within 1e-5 of a half range of the ticks' worst."""
    rng = np.random.default_rng(7)
    runs = random_params(rng, 10) + random_params(rng, 2, moves_per_run=2)
    fast = judge_plans(runs)
    ticks = judge_plans(runs, planner=hp.PaperMovePlanner())
    exceeded = 0
    for a, b in zip(fast, ticks, strict=True):
        assert [c.name for c in a] == [c.name for c in b]
        for x, y in zip(a, b, strict=True):
            if x.name == "pose_limits":
                assert x.value == pytest.approx(y.value, abs=1e-5)
                exceeded += x.value > 1.0
            elif x.name == "hexapod_speed":
                # The same formula, on the pose of the fast path's forward kinematics (to
                # FK_TOLERANCE_M) and of every tick's: equal to round-off.
                assert x.value == pytest.approx(y.value, rel=1e-9), (x, y)
            else:
                assert x.value == y.value, (x, y)
    assert exceeded  # these seeds include paths that leave the pose limits


def test_multi_move_run_reports_its_worst_move():
    rng = np.random.default_rng(3)
    [run] = random_params(rng, 1, moves_per_run=3)
    [whole] = judge_plans([run])
    single = []
    for move in problems(run):
        params = HexapodParams(
            start_pose=pose_mm_deg(move.start_pose),
            moves=(HexapodMove(pose_mm_deg(move.target_pose), move.synchronous),),
        )
        single.append(by_name(judge_plans([params])[0]))
    whole = by_name(whole)
    for name, check in whole.items():
        values = [s[name].value for s in single if name in s]
        assert check.value == pytest.approx(max(values), rel=1e-12, abs=1e-12), name


def test_batch_equals_one_at_a_time_bit_for_bit():
    rng = np.random.default_rng(11)
    runs = random_params(rng, 40) + random_params(rng, 5, moves_per_run=3)
    rng.shuffle(runs)
    batch = judge_plans(runs)
    for params, checks in zip(runs, batch, strict=True):
        [alone] = judge_plans([params])
        assert [(c.name, float(c.value).hex(), c.limit, c.unit, c.note) for c in checks] == [
            (c.name, float(c.value).hex(), c.limit, c.unit, c.note) for c in alone
        ]


# ----------------------------------------------------------------------------- bad plans fail


class TimeScaled:
    """A trajectory played ``factor`` times faster (its speeds x factor, accelerations x
    factor^2)."""

    def __init__(self, trajectory, factor):
        self.trajectory, self.factor = trajectory, factor
        self.labels = trajectory.labels
        self.duration = trajectory.duration / factor

    def sample(self, t):
        s = self.trajectory.sample(np.asarray(t, dtype=float) * self.factor)
        return TrajectorySample(
            np.asarray(t, dtype=float), s.position, s.velocity * self.factor, s.acceleration * self.factor**2
        )


class Shifted:
    """A trajectory with ``offset`` (6,) m added to its strut positions from t = 0 on."""

    def __init__(self, trajectory, offset):
        self.trajectory, self.offset = trajectory, np.asarray(offset, dtype=float)
        self.labels, self.duration = trajectory.labels, trajectory.duration

    def sample(self, t):
        s = self.trajectory.sample(t)
        return TrajectorySample(s.t, s.position + self.offset, s.velocity, s.acceleration)


class HastyPlanner:
    """The paper's moves played twice as fast: over the strut speed and acceleration limits."""

    def plan(self, problem):
        return TimeScaled(hp.PaperMovePlanner().plan(problem), 2.0)


def test_a_planner_over_the_strut_limits_fails():
    params = scenarios.get("hexapod-sync-move").params
    [checks] = judge_plans([params], planner=HastyPlanner())
    c = by_name(checks)
    assert not c["strut_velocity"].passed and c["strut_velocity"].value > 900
    assert not c["strut_accel"].passed and c["strut_accel"].value > 1800
    assert c["arrival_spread"].passed and c["plan_pose_error_final"].passed


def test_hand_made_bad_trajectories_fail():
    [move] = problems(scenarios.get("hexapod-sync-move").params)
    paper = hp.PaperMovePlanner().plan(move)
    # 5 um too long on one strut: the planned end is not the target pose.
    off = by_name(judge_trajectories([move], [Shifted(paper, [5e-6, 0, 0, 0, 0, 0])]))
    assert not off["plan_pose_error_final"].passed and off["plan_pose_error_final"].value > 1.0
    # 12 mm longer on every strut: beyond the 14.1 mm stroke and, lifting the platform, the
    # z limit (13.1 mm).
    far = by_name(judge_trajectories([move], [Shifted(paper, np.full(6, 12e-3))]))
    assert not far["plan_stroke"].passed and far["plan_stroke"].value > 14.1
    assert not far["pose_limits"].passed and "z =" in far["pose_limits"].note

    # A move that never comes to rest: its arrivals cannot be judged.
    class Moving(Shifted):
        def sample(self, t):
            s = super().sample(t)
            return TrajectorySample(s.t, s.position, s.velocity + 1e-6, s.acceleration)

    restless = by_name(judge_trajectories([move], [Moving(paper, np.zeros(6))]))
    assert not restless["arrival_spread"].passed and not restless["arrival_spread"].evaluated


# ----------------------------------------------------------------------------- random moves


def _pose(draw):
    low, high = hp.RUBIN_LIMITS.pose_lower, hp.RUBIN_LIMITS.pose_upper
    return np.array([draw(st.floats(float(lo), float(hi), allow_nan=False)) for lo, hi in zip(low, high, strict=True)])


@st.composite
def runs(draw):
    """A valid run of one or two moves (poses inside the limits and the stroke)."""
    poses = [_pose(draw) for _ in range(draw(st.integers(2, 3)))]
    for pose in poses:
        assume(np.all(np.abs(hp.strut_positions(pose)) <= hp.RUBIN_LIMITS.stroke))
    moves = tuple(HexapodMove(pose_mm_deg(p), draw(st.booleans())) for p in poses[1:])
    try:
        return HexapodParams(start_pose=pose_mm_deg(poses[0]), moves=moves)
    except ParamError:
        assume(False)


@settings(max_examples=60)
@given(runs())
def test_random_valid_moves_pass_the_limits_the_generator_keeps(params):
    """The paper's generator keeps the strut limits, the stroke, the arrivals and the target
    by construction; the pose limits along the path it does not (module docstring): that
    check is evaluated, at least the worst of the run's end poses."""
    [checks] = judge_plans([params])
    c = by_name(checks)
    for name in KEPT:
        if name in c:
            assert c[name].passed, c[name]
    low, high = hp.RUBIN_LIMITS.pose_lower, hp.RUBIN_LIMITS.pose_upper
    centre, half = (low + high) / 2, (high - low) / 2
    ends = [params.start_pose] + [m.target for m in params.moves]
    worst_end = max(np.abs((pose_si(p) - centre) / half).max() for p in ends)
    assert c["pose_limits"].evaluated and c["pose_limits"].value >= worst_end - 1e-12


# ----------------------------------------------------------------------------- the kernels


@given(
    st.lists(
        st.lists(
            st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.just(0.0), st.just(-0.0)),
            min_size=6,
            max_size=6,
        ),
        min_size=1,
        max_size=20,
    )
)
def test_max_of_the_last_axis_is_numpys(rows):
    from planbench.hexapod.plan_checks import _max_last

    values = np.array(rows)
    np.testing.assert_array_equal(_max_last(values), values.max(axis=-1))
    np.testing.assert_array_equal(_max_last(values.reshape(-1, 2, 3)), values.reshape(-1, 2, 3).max(axis=-1))


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 40))
def test_the_nearest_anchor_is_the_argmin_of_the_distances(seed, count):
    from planbench.hexapod.plan_checks import _Anchors

    rng = np.random.default_rng(seed)
    start, target = hp.random_poses(count, rng), hp.random_poses(count, rng)
    anchors = _Anchors(hp.plan_moves(start, target, synchronous=bool(seed % 2), method="closed"))
    rows = rng.integers(0, count, 3 * count)
    # Positions between and at the anchors (exact ties: the first anchor, as argmin).
    position = anchors.struts[rows, rng.integers(0, 3, rows.size)]
    position[::2] += rng.uniform(-1, 1, (position[::2].shape[0], 6)) * 1e-3
    distance = np.abs(position[:, None, :] - anchors.struts[rows]).max(axis=-1)
    np.testing.assert_array_equal(anchors.nearest(rows, position), 3 * rows + np.argmin(distance, axis=1))
    # Exact ties go to the first anchor, as argmin's.
    tied = object.__new__(_Anchors)
    tied.struts = np.broadcast_to(np.array([0.0, 2.0, 4.0])[None, :, None], (2, 3, 6)).copy()
    np.testing.assert_array_equal(
        tied.nearest(np.array([0, 1, 1]), np.array([[1.0] * 6, [3.0] * 6, [2.0] * 6])), [0, 3 + 1, 3 + 1]
    )


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 2**32 - 1), st.booleans())
def test_a_repeated_sample_time_takes_the_pose_its_own_solve_would_reach(seed, synchronous):
    """Switching ticks that struts share repeat a sample time; the judge solves such a time
    once. Solving every repeat on its own gives the same poses and residuals, bit for bit."""
    from planbench.hexapod.plan_checks import _Anchors, _poses_along, _sample_rows, _switching_ticks

    rng = np.random.default_rng(seed)
    start, target = hp.random_poses(30, rng), hp.random_poses(30, rng)
    moves = hp.plan_moves(start, target, synchronous=synchronous, method="closed")
    ticks = _switching_ticks(moves)
    times = np.empty((len(moves), 2 * ticks.shape[1] - 1))
    times[:, 0::2] = ticks * moves.dt
    times[:, 1::2] = 0.5 * (ticks[:, :-1] + ticks[:, 1:]) * moves.dt
    position = _sample_rows(moves, np.repeat(np.arange(len(moves)), times.shape[1]), times.ravel()).position
    position = position.reshape(len(moves), -1, 6)
    fresh = np.ones(times.shape, dtype=bool)
    fresh[:, 1:] = times[:, 1:] != times[:, :-1]
    assert not fresh.all()  # struts share switching ticks in such moves
    anchors = _Anchors(moves)
    once, once_residual = _poses_along(anchors, position, fresh)
    every, every_residual = _poses_along(anchors, position, np.ones_like(fresh))
    np.testing.assert_array_equal(once, every)
    np.testing.assert_array_equal(once_residual, every_residual)
