"""FAST scenario parameters refused before any work: the start time's years (whatever else the
parameters say), a wind file's direction beyond one turn, the source given twice or not at all."""

import re

import pytest

from planbench import fast
from planbench.params import ParamError
from planbench.wind import MAX_DIRECTION_DEG, MeasuredWind, WindFileError

RADEC = [202.78, 30.51]


@pytest.mark.parametrize("cls", [fast.FastTrackingParams, fast.FastScanParams, fast.FastSwitchParams])
@pytest.mark.parametrize("start", ["2100-01-01T00:00:00", "1971-12-31T23:59:59"])
def test_start_utc_outside_1972_2099_is_refused(cls, start):
    with pytest.raises(ParamError, match=rf"^start_utc = '{start}' is outside the years 1972-2099"):
        cls.from_mapping({"start_utc": start})


@pytest.mark.parametrize(
    "mapping, words",
    [
        (
            {"source": "3C 286", "source_radec": RADEC},
            r"^source = '3C 286' and source_radec = \[202.78, 30.51\] are both given: give one",
        ),
        ({"source": None}, r"^source and source_radec are both none: give one"),
    ],
)
def test_source_and_radec_one_of_them(mapping, words):
    with pytest.raises(ParamError, match=words):
        fast.FastTrackingParams.from_mapping(mapping)


def test_radec_alone_clears_the_catalogue_source():
    p = fast.FastTrackingParams.from_mapping({"source_radec": RADEC})
    assert p.source is None and p.source_radec == tuple(RADEC)


@pytest.mark.parametrize(
    "direction, ok", [(1e9, False), (-360.5, False), (361.0, False), (360.0, True), (-360.0, True), (45.0, True)]
)
def test_wind_file_direction_beyond_one_turn_is_refused(tmp_path, direction, ok):
    path = tmp_path / "wind.csv"
    path.write_text(f"t,speed,direction\n0,4,10\n1,4,{direction!r}\n2,4,10\n")
    if ok:
        assert MeasuredWind(path).direction[1] == direction
        return
    with pytest.raises(
        WindFileError,
        match=rf"line 3: direction {re.escape(f'{direction:g}')} deg is outside "
        rf"\[-{MAX_DIRECTION_DEG:g}, {MAX_DIRECTION_DEG:g}\] deg",
    ):
        MeasuredWind(path)


def test_dut1_reaches_the_plan():
    """UT1 - UTC = +0.5 s: the transit, hence the default observation's start, 0.5 s earlier in UTC."""
    from planbench.planners.fast import sky

    a = fast.goal_plan(fast.FastTrackingParams(tracking=60.0))
    b = fast.goal_plan(fast.FastTrackingParams(tracking=60.0, dut1=0.5))
    ta = sky.as_utc_jd(a.info["observation_start_utc"])
    tb = sky.as_utc_jd(b.info["observation_start_utc"])
    shift = ((ta[0] - tb[0]) + (ta[1] - tb[1])) * 86400.0
    assert float(shift) == pytest.approx(0.5, abs=2e-3)


@pytest.mark.parametrize("dut1", [0.9, -0.9, 5.0])
def test_dut1_outside_09_s_is_refused(dut1):
    with pytest.raises(ParamError, match=rf"^dut1 = {dut1:g} s is outside \(-0.9, 0.9\) s"):
        fast.FastTrackingParams(dut1=dut1)
