"""runtime/state.py reads the state layout from the generated SR_X_* macros and names every block once."""
import numpy as np

from bindings._sr import lib
from runtime import state
from runtime.so3 import random_rotation, rot_x, rot_y

BLOCKS = {"R_S": state.IDX_RS, "R_Y": state.IDX_RY, "R_P": state.IDX_RP, "q": state.IDX_Q,
          "w_S": state.IDX_WS, "w_Y": state.IDX_WY, "w_P": state.IDX_WP}


def test_every_block_starts_at_its_generated_offset():
    for name, idx in BLOCKS.items():
        start = idx.start if isinstance(idx, slice) else idx
        assert start == getattr(lib, f"SR_X_{name}"), name
    assert (state.NX, state.NU, state.NV) == (lib.SR_NX, lib.SR_NU, lib.SR_NV)
    assert (state.IDX_UY, state.IDX_UP) == (lib.SR_U_u_Y, lib.SR_U_u_P)


def test_the_blocks_cover_the_state_once_and_nu_is_the_speeds():
    owner = np.zeros(state.NX, dtype=int)
    for idx in BLOCKS.values():
        owner[idx] += 1
    assert (owner == 1).all()
    x = np.arange(state.NX, dtype=float)
    assert x[state.IDX_NU].tolist() == [*x[state.IDX_WS], x[state.IDX_WY], x[state.IDX_WP]]
    assert x[state.IDX_QZ] == x[state.IDX_Q][2]


def test_initial_state_puts_each_argument_in_its_block(rng):
    R_S = random_rotation(rng)
    x = state.initial_state(0.3, -0.7, R_S=R_S, q=(1.0, 2.0, 0.3), w_S=(4.0, 5.0, 6.0), w_Y=7.0, w_P=8.0)
    R_s, R_y, R_p = state.rotations(x)
    assert np.array_equal(R_s, R_S)
    assert np.array_equal(R_y, rot_x(0.3)) and np.array_equal(R_p, rot_y(-0.7))
    assert x[state.IDX_Q].tolist() == [1.0, 2.0, 0.3]
    assert x[state.IDX_NU].tolist() == [4.0, 5.0, 6.0, 7.0, 8.0]
    assert np.array_equal(state.gamma(x), R_S[2])


def test_angles_read_back_from_a_batch_of_states():
    thetas = np.linspace(-3.0, 3.0, 7)
    X = np.array([state.initial_state(t, -t) for t in thetas])
    assert np.allclose(state.yoke_angle(X), thetas, atol=1e-15)
    assert np.allclose(state.pendulum_angle(X), -thetas, atol=1e-15)
    assert state.rotations(X)[0].shape == (7, 3, 3)


def test_absolute_inclinations_are_the_angles_to_the_vertical():
    x = state.initial_state(0.4, 0.0)
    yoke, pendulum = state.absolute_inclinations(x)
    assert np.isclose(yoke, 0.4) and np.isclose(pendulum, 0.4)
    yoke, pendulum = state.absolute_inclinations(state.initial_state(0.0, -0.25))
    assert np.isclose(yoke, 0.0) and np.isclose(pendulum, 0.25)
