"""What a plant perturbation may change in a compiled model, for the plant-uncertainty tests
(tests/test_loader_plant.py, tests/test_hexapod_plant.py).

``assert_edits_only(nominal, plant, edits)``: the plant's model is the nominal one with the
``edits`` (the rows of the MjModel fields that the perturbation sets, at the values computed by
hand) and nothing else, apart from what MuJoCo derives from them at compile time
(``mj_setConst``: subtree masses, invweights, dof_M0, ...): the nominal model with those rows
written and ``mj_setConst`` run equals the plant's bit for bit.
"""

from __future__ import annotations

import copy

import mujoco
import numpy as np
from model_diff import changed_fields


def assert_edits_only(
    nominal: mujoco.MjModel, plant: mujoco.MjModel, edits: dict, rtol: float = 1e-12, roundoff: tuple = ()
) -> dict:
    """Assert that ``plant`` is ``nominal`` with ``edits`` ({field: {row: expected value}}).

    Rows of an edited field other than those given must be unchanged; the given ones must
    equal their expected value to ``rtol`` (round-off of MuJoCo's sums: a row whose expected
    value is the nominal one may differ by that). Every other field must be what MuJoCo
    derives from the edited ones: bit for bit, or to ``rtol`` for the fields ``roundoff``
    (compile-time ones that follow an edited row's round-off, such as the bounding volumes
    of a body whose centre of mass moved by 1e-17 m). Returns ``changed_fields(nominal, plant)``.
    """
    diff = changed_fields(nominal, plant)
    for name, rows in edits.items():
        changed = set(diff.get(name, np.array([], dtype=int)).tolist())
        assert changed <= set(rows), f"{name}: rows {sorted(changed - set(rows))} changed, not only {sorted(rows)}"
        for row, value in rows.items():
            np.testing.assert_allclose(
                getattr(plant, name)[row], value, rtol=rtol, atol=1e-15, err_msg=f"{name}[{row}]"
            )
    expected = copy.copy(nominal)
    for name, rows in edits.items():
        for row in rows:
            getattr(expected, name)[row] = getattr(plant, name)[row]
    mujoco.mj_setConst(expected, mujoco.MjData(expected))
    rest = changed_fields(expected, plant)
    for name in roundoff:
        if name in rest:
            np.testing.assert_allclose(
                getattr(plant, name), getattr(expected, name), rtol=rtol, atol=1e-15, err_msg=name
            )
            del rest[name]
    assert rest == {}, (
        f"fields changed beyond the edits and what MuJoCo derives from them: "
        f"{ {k: v.tolist() for k, v in rest.items()} }"
    )
    return diff
