"""transforms: the one home of rotations and poses (roll-pitch-yaw, quaternions, their matrices, planar yaw,
poses composed and inverted, heading differences), checked against the conventions every caller relies on:
fixed-axis R = Rz(yaw) Ry(pitch) Rx(roll) as URDF and SDF define it, tf's ``quaternion_from_euler`` (axes
'sxyz', what spawn_model sends) and PyBullet's own conversion.
"""
import math

import numpy as np
import pytest

from diffbot_sim.transforms import (
    compose,
    inverse,
    matrix_rpy,
    qconj,
    qmul,
    qnormalize,
    quaternion_from_yaw,
    quaternion_matrix,
    quaternion_rpy,
    roll_pitch_from_quaternion,
    rotate,
    rpy_matrix,
    rpy_quaternion,
    wrap_angle,
    yaw_from_quaternion,
)


def near(a, b, tol=1e-9):
    return len(a) == len(b) and all(abs(x - y) <= tol for x, y in zip(a, b))


def same_rotation(q, r, tol=1e-9):
    """q and -q are the same rotation."""
    return near(q, r, tol) or near(q, tuple(-c for c in r), tol)


# ------------------------------------------------------------------------------------------ roll, pitch, yaw

@pytest.mark.parametrize("rpy, expected", [
    ((0, 0, math.pi / 2), (0, 0, math.sqrt(0.5), math.sqrt(0.5))),
    ((math.pi, 0, 0), (1, 0, 0, 0)),
    ((0, math.pi / 2, 0), (0, math.sqrt(0.5), 0, math.sqrt(0.5))),
    # tf.transformations.quaternion_from_euler(0.1, 0.2, 0.3) (axes 'sxyz'; scipy from_euler("xyz") agrees)
    ((0.1, 0.2, 0.3), (0.034270798550482096, 0.10602051106179562, 0.1435721750273919, 0.9833474432563558)),
])
def test_rpy_quaternion_is_tfs_quaternion_from_euler(rpy, expected):
    assert rpy_quaternion(*rpy) == pytest.approx(expected, abs=1e-12)


def test_rpy_quaternion_is_fixed_axis_roll_pitch_yaw():
    # yaw 90 degrees turns +x into +y; roll then yaw: R = Rz Ry Rx (SDF / URDF convention)
    q = rpy_quaternion(0, 0, math.pi / 2)
    assert near(compose(((0, 0, 0), q), ((1, 0, 0), (0, 0, 0, 1)))[0], (0, 1, 0))
    q = rpy_quaternion(math.pi / 2, 0, math.pi / 2)  # roll: y -> z; then yaw: unchanged z
    assert near(compose(((0, 0, 0), q), ((0, 1, 0), (0, 0, 0, 1)))[0], (0, 0, 1))
    composed = qmul(rpy_quaternion(0, 0, 0.3), qmul(rpy_quaternion(0, -0.2, 0), rpy_quaternion(0.1, 0, 0)))
    assert rpy_quaternion(0.1, -0.2, 0.3) == pytest.approx(composed)


@pytest.mark.parametrize("rpy", [(0.3, -0.4, 1.1), (0.0, 0.0, -2.5), (1.2, 0.7, 0.0), (-3.0, 1.5, 2.0)])
def test_quaternion_matrix_is_the_rpy_matrix(rpy):
    """Static xyz: the matrix of the quaternion of (r, p, y) is Rz(yaw) Ry(pitch) Rx(roll)."""
    assert quaternion_matrix(rpy_quaternion(*rpy)) == pytest.approx(rpy_matrix(rpy), abs=1e-12)


def test_quaternion_matrix_turns_vectors_as_rotate():
    q = qnormalize((0.2, -0.5, 0.4, 0.7))
    for v in ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.3, -2.0, 5.0)):
        assert quaternion_matrix(q) @ np.array(v) == pytest.approx(rotate(q, v), abs=1e-12)


@pytest.mark.parametrize("roll, pitch", [(0.5, 0.0), (0.0, 0.3), (-0.4, 0.2), (2.5, -1.2)])
def test_roll_pitch_from_quaternion(roll, pitch):
    assert roll_pitch_from_quaternion(*rpy_quaternion(roll, pitch, 0.7)) == pytest.approx((roll, pitch))


def test_roll_pitch_at_pitch_beyond_one_stays_defined():
    """Rounding can push 2 (w y - z x) a hair past 1 at pitch pi/2: asin must not raise."""
    s = math.sqrt(0.5) * (1 + 1e-15)
    assert roll_pitch_from_quaternion(0.0, s, 0.0, s)[1] == pytest.approx(math.pi / 2)


# ------------------------------------------------------------------------------------------ quaternions

def test_quaternion_product_conjugate_and_normalize():
    q = rpy_quaternion(0, 0, math.pi / 2)
    assert q == pytest.approx((0, 0, math.sqrt(0.5), math.sqrt(0.5)))
    assert rotate(q, (1, 0, 0)) == pytest.approx((0, 1, 0))
    assert qmul(q, qconj(q)) == pytest.approx((0, 0, 0, 1))
    assert qnormalize((0, 0, 0, 2)) == (0.0, 0.0, 0.0, 1.0)
    assert qnormalize((0, 0, 0, 0)) == (0.0, 0.0, 0.0, 1.0)


def test_compose_and_inverse_round_trip():
    a = ((1.0, 2.0, 3.0), rpy_quaternion(0.1, -0.2, 0.7))
    b = ((-0.5, 0.25, 2.0), rpy_quaternion(0.3, 0.4, -1.0))
    back = compose(inverse(a), compose(a, b))
    assert near(back[0], b[0]) and same_rotation(back[1], b[1])


# ------------------------------------------------------------------------------------------ planar yaw

def test_yaw_from_quaternion():
    half = math.radians(30.0) / 2
    assert yaw_from_quaternion(0.0, 0.0, math.sin(half), math.cos(half)) == pytest.approx(math.radians(30.0))
    assert yaw_from_quaternion(0.0, 0.0, 0.0, 1.0) == 0.0
    assert yaw_from_quaternion(0.0, 0.0, 1.0, 0.0) == pytest.approx(math.pi)
    assert yaw_from_quaternion(0, 0, math.sin(0.4), math.cos(0.4)) == pytest.approx(0.8)
    # roll and pitch do not change the heading
    assert yaw_from_quaternion(*rpy_quaternion(0.2, -0.1, 1.3)) == pytest.approx(1.3)


def test_planar_quaternion_round_trip():
    for yaw in (-3.0, -1.0, 0.0, 0.5, 3.0):
        assert yaw_from_quaternion(*quaternion_from_yaw(yaw)) == pytest.approx(yaw)
        assert quaternion_from_yaw(yaw) == pytest.approx(rpy_quaternion(0.0, 0.0, yaw))
    assert quaternion_from_yaw(math.pi / 2)[2] == pytest.approx(math.sqrt(0.5))


def test_yaw_from_quaternion_matches_pybullet():
    pybullet = pytest.importorskip("pybullet")
    for yaw in (0.0, 0.5, -2.0, 3.0):
        assert yaw_from_quaternion(*pybullet.getQuaternionFromEuler((0.0, 0.0, yaw))) == pytest.approx(yaw, abs=1e-6)


@pytest.mark.parametrize("angle, turn", [(0.0, 0.0), (math.pi / 2, math.pi / 2), (3 * math.pi / 2, -math.pi / 2),
                                         (-3 * math.pi / 2, math.pi / 2), (2 * math.pi + 0.1, 0.1),
                                         (-7.0, -7.0 + 2 * math.pi)])
def test_wrap_angle(angle, turn):
    """A heading difference as the turn it is (the tour steers by it, drive checks judge by it)."""
    assert wrap_angle(angle) == pytest.approx(turn)


# ------------------------------------------------------------------------------------------ to angles

def ign_euler(q):
    """ignition-math6's ``Quaternion::Euler`` (6.9.2, include/ignition/math/Quaternion.hh) transcribed as the
    reference: normalise, pitch = asin(-2 (xz - wy)) clamped; at |sin pitch -+ 1| < 1e-15 yaw is 0 and roll
    carries the rest."""
    n = math.sqrt(sum(c * c for c in q))
    x, y, z, w = (c / n for c in q) if n > 1e-6 else (0.0, 0.0, 0.0, 1.0)
    squ, sqx, sqy, sqz = w * w, x * x, y * y, z * z
    sarg = -2 * (x * z - w * y)
    pitch = -math.pi / 2 if sarg <= -1 else math.pi / 2 if sarg >= 1 else math.asin(sarg)
    if abs(sarg - 1) < 1e-15:
        return math.atan2(2 * (x * y - z * w), squ - sqx + sqy - sqz), pitch, 0.0
    if abs(sarg + 1) < 1e-15:
        return math.atan2(-2 * (x * y - z * w), squ - sqx + sqy - sqz), pitch, 0.0
    return (math.atan2(2 * (y * z + w * x), squ - sqx - sqy + sqz), pitch,
            math.atan2(2 * (x * y + w * z), squ + sqx - sqy - sqz))


def test_quaternion_rpy_is_ignition_maths_euler():
    rng = np.random.default_rng(7)
    for q in rng.normal(size=(500, 4)):
        assert near(quaternion_rpy(q), ign_euler(q), 1e-9), q
    assert near(quaternion_rpy((0.0, 0.0, 0.0, 2.0)), (0.0, 0.0, 0.0))  # not normalised: normalised first


@pytest.mark.parametrize("pitch", [math.pi / 2, -math.pi / 2])
@pytest.mark.parametrize("roll, yaw", [(0.0, 0.0), (0.4, -1.0), (-2.0, 2.5)])
def test_at_gimbal_lock_yaw_is_zero_and_roll_carries_the_rest_as_in_ignition(roll, pitch, yaw):
    q = rpy_quaternion(roll, pitch, yaw)
    out = quaternion_rpy(q)
    assert out[1] == pytest.approx(pitch, abs=1e-7) and out[2] == 0.0
    assert abs(wrap_angle(out[0] - ign_euler(q)[0])) < 1e-7
    assert near(rpy_quaternion(*out), q, 1e-7) or near(rpy_quaternion(*out), tuple(-c for c in q), 1e-7)
    m = rpy_matrix((roll, pitch, yaw))
    assert matrix_rpy(m)[2] == 0.0 and np.allclose(rpy_matrix(matrix_rpy(m)), m, atol=1e-9)


def test_pitch_stays_exact_next_to_gimbal_lock_where_asin_loses_digits():
    pitch = math.pi / 2 - 1e-7
    q = rpy_quaternion(0.3, pitch, -0.2)
    assert quaternion_rpy(q)[1] == pytest.approx(pitch, abs=1e-12)
    assert matrix_rpy(rpy_matrix((0.3, pitch, -0.2))) == pytest.approx((0.3, pitch, -0.2), abs=1e-9)
    assert abs(ign_euler(q)[1] - pitch) > 1e-11  # why the angle is read from the matrix with atan2


def test_matrix_rpy_returns_floats_from_a_numpy_matrix():
    out = matrix_rpy(rpy_matrix((0.1, 0.2, 0.3)))
    assert out == pytest.approx((0.1, 0.2, 0.3), abs=1e-12) and all(type(v) is float for v in out)
