"""A user's controller for FAST: the winches' feed-forward alone, no feedback, no stabilizer.

Run it:  planbench run fast-tracking --controller examples/fast/feedforward_controller.py:FeedforwardOnly

The winches pay out the unstretched lengths that give the planned cable lengths under the
planned tensions (elastic stretch and sag, the same law as the plant's); the A-B rotator
holds the planned angles; the Stewart legs hold their nominal lengths; the multi-beam
rotation follows its plan. Nothing reads the sensors, so wind and the A-B's weight move the
feed freely: the feed is as good as the cable robot alone.
"""

from __future__ import annotations

import numpy as np

from planbench.fast.controller import winch_feedforward
from planbench.planners import fast
from planbench.planners.fast import plan as fp


class FeedforwardOnly:
    def reset(self, context) -> None:
        state = fp.reference_state(context.reference)  # cabin pose and tensions of the plan
        self.winch = winch_feedforward(state, fast.FAST.tower_anchors)
        self.ab = np.column_stack([state.theta_a, state.theta_b])
        self.multifeed = state.multifeed
        names = context.actuators
        self.cables = [names.index(f"cable{i}") for i in range(1, 7)]
        self.ab_drives = [names.index("ab_a"), names.index("ab_b")]
        self.legs = [names.index(f"leg{i}") for i in range(1, 7)]
        self.multifeed_drive = names.index("multifeed")
        self.command = context.command
        self(0, context.observation)

    def __call__(self, tick: int, observation) -> None:
        k = min(tick + 1, len(self.winch) - 1)
        c = self.command
        c[self.cables] = self.winch[k]
        c[self.ab_drives] = self.ab[k]
        c[self.legs] = 0.0  # the legs' set-point rates: hold nominal
        c[self.multifeed_drive] = self.multifeed[k]
