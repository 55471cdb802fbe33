"""transforms.wrap_angle: a heading difference as the turn it is (the tour steers by it, drive checks judge by it)."""
import math

import pytest

from diffbot_sim.transforms import wrap_angle


@pytest.mark.parametrize("angle, turn", [(0.0, 0.0), (math.pi / 2, math.pi / 2), (3 * math.pi / 2, -math.pi / 2),
                                         (-3 * math.pi / 2, math.pi / 2), (2 * math.pi + 0.1, 0.1), (-7.0, -7.0 + 2 * math.pi)])
def test_wrap_angle(angle, turn):
    assert wrap_angle(angle) == pytest.approx(turn)
