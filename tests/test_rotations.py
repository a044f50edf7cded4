"""planbench.planners.rotations: the shared rotation helpers against numpy, scipy and MuJoCo."""

import mujoco
import numpy as np
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from scipy.spatial.transform import Rotation

from planbench.planners.rotations import rot_x, rot_y, rot_z, skew, vee, wxyz

vectors = arrays(float, 3, elements=st.floats(-10, 10))


@given(vectors, vectors)
def test_skew_is_the_cross_product_and_vee_its_inverse(v, u):
    np.testing.assert_allclose(skew(v) @ u, np.cross(v, u), atol=1e-12)
    np.testing.assert_allclose(vee(skew(v)), v, atol=0)
    np.testing.assert_array_equal(skew(np.stack([v, u]))[1], skew(u))  # vectorized


@given(arrays(float, 3, elements=st.floats(-1e-3, 1e-3)))
def test_vee_of_a_small_rotation_is_its_rotation_vector(w):
    r = Rotation.from_rotvec(w).as_matrix()
    np.testing.assert_allclose(vee(r), w, atol=1e-9)


@given(arrays(float, 3, elements=st.floats(-3, 3)))
def test_wxyz_is_mujocos_quaternion(angles):
    r = rot_z(angles[0]) @ rot_y(angles[1]) @ rot_x(angles[2])
    q = wxyz(r)
    back = np.empty(9)
    mujoco.mju_quat2Mat(back, q)
    np.testing.assert_allclose(back.reshape(3, 3), r, atol=1e-12)
    assert wxyz(np.stack([r, r.T])).shape == (2, 4)
