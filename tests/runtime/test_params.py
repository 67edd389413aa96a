"""Params and PaperParams: their field orders are the C library's (SR_P_*, SR_PAPER_*), and their
validity is decided by C's sr_check_params and sr_check_paper_params."""
import math
import types

import numpy as np
import pytest

from bindings._sr import ffi, lib
from runtime import Params
from runtime.params import FLAT_FIELDS, NAMES, PAPER_NAMES, PaperParams, parameter_order


def rule_text(rule):
    return ffi.string(lib.sr_param_rule_string(rule)).decode()


# -- order -----------------------------------------------------------------------------------------
def test_every_paper_field_sits_at_its_c_index():
    assert len(PAPER_NAMES) == lib.SR_NPAPER
    assert [getattr(lib, f"SR_PAPER_{name}") for name in PAPER_NAMES] == list(range(lib.SR_NPAPER))


def test_every_entry_of_the_c_vector_belongs_to_one_field():
    assert len(FLAT_FIELDS) == lib.SR_NPARAM
    assert {name for name, _ in FLAT_FIELDS} == set(NAMES)


def test_as_array_puts_each_value_at_its_c_index():
    p = Params(m_P=1.25, k_P=0.07, c_Y=(0.01, -0.02, 0.03), J_Y=[[0.2, 0.01, 0], [0.01, 0.3, 0], [0, 0, 0.4]])
    values = p.as_array()
    assert values[lib.SR_P_m_P] == 1.25 and values[lib.SR_P_k_P] == 0.07
    assert values[lib.SR_P_c_Y_y] == -0.02 and values[lib.SR_P_J_Y_xy] == 0.01 and values[lib.SR_P_J_Y_zz] == 0.4


def test_from_array_inverts_as_array():
    p = Params(c_P=(0.01, 0.0, -0.1), J_P=[[0.004, 0.0005, 0.0002], [0.0005, 0.0035, 0.0001], [0.0002, 0.0001, 0.0015]])
    assert Params.from_array(p.as_array()) == p


def fake_library(**indices):
    return types.SimpleNamespace(SR_NPARAM=len(indices), **{f"SR_P_{k}": v for k, v in indices.items()})


def test_parameter_order_follows_the_library_not_the_declaration():
    assert parameter_order(("a", "b", "c"), fake_library(a=2, b=0, c=1)) == ("b", "c", "a")


def test_parameter_order_refuses_a_field_the_library_lacks():
    with pytest.raises(ValueError, match="no SR_P_ index in the C library for c"):
        parameter_order(("a", "b", "c"), fake_library(a=0, b=1))


def test_parameter_order_refuses_a_library_parameter_without_field():
    with pytest.raises(ValueError, match="do not match"):
        parameter_order(("a", "b"), fake_library(a=0, b=1, c=2))


def test_parameter_order_refuses_a_repeated_index():
    with pytest.raises(ValueError, match="do not match"):
        parameter_order(("a", "b"), fake_library(a=0, b=0))


# -- the paper's robot -------------------------------------------------------------------------------
def test_the_default_robot_is_the_papers():
    assert Params() == Params.paper() and Params().paper_params == PaperParams()


def test_the_papers_robot_has_its_rods_tensors():
    """Section 2.3: j_xx = (m_b/6 + m_h/2) b², j_yy = (m_b/2 + m_h/6) h², a planar yoke, a slender rod."""
    p, q = Params.paper(), PaperParams()
    j_xx, j_yy = (q.m_b / 6 + q.m_h / 2) * q.b**2, (q.m_b / 2 + q.m_h / 6) * q.h**2
    np.testing.assert_allclose(p.J_Y, np.diag([j_xx, j_yy, j_xx + j_yy]), rtol=1e-15)
    np.testing.assert_allclose(p.J_P, q.m_P * q.l**2 / 12 * np.diag([1, 1, 0]), rtol=1e-15)
    assert p.c_P == (0.0, 0.0, -q.l / 2) and p.c_Y == (0.0, 0.0, 0.0)
    assert p.m_Y == 2 * (q.m_b + q.m_h) and p.j_S == pytest.approx(2 / 3 * q.m_S * q.r**2, rel=1e-15)
    assert (p.j_mY, p.j_mP, p.n_Y, p.n_P, p.slope) == (0.0, 0.0, 1.0, 1.0, 0.0)


def test_paper_simulation_doubles_the_printed_damping():
    p = Params.paper_simulation(m_P=1.5)
    assert (p.k_S, p.k_Y, p.k_P) == (0.16, 0.04, 0.1) and p.paper_params.m_P == 1.5 and p.m_P == 1.5


def test_changing_a_general_field_forgets_the_papers_description():
    assert Params().replace(slope=0.1).paper_params is None


# -- validity: the messages name the field and C's rule ------------------------------------------
@pytest.mark.parametrize("name", PAPER_NAMES)
def test_a_non_finite_paper_value_is_named(name):
    with pytest.raises(ValueError, match=rf"^Params\.{name}: {rule_text(lib.SR_PARAM_RULE_FINITE)}, got nan$"):
        Params.paper(**{name: math.nan})


@pytest.mark.parametrize("name", ["r", "m_S", "j_S", "k_S", "m_Y", "k_Y", "m_P", "k_P", "j_mY", "n_Y", "j_mP", "n_P",
                                  "g", "slope"])
def test_a_non_finite_general_value_is_named(name):
    with pytest.raises(ValueError, match=rf"^Params\.{name}: {rule_text(lib.SR_PARAM_RULE_FINITE)}, got nan$"):
        Params(**{name: math.nan})


def test_a_non_finite_entry_of_a_tensor_is_named():
    J = np.diag([0.1, 0.2, 0.3])
    J[2, 2] = math.inf
    with pytest.raises(ValueError, match=r"^Params\.J_Y\[\(2, 2\)\]: must be finite, got inf$"):
        Params(J_Y=J)


@pytest.mark.parametrize("name", ["r", "m_S", "b", "h", "m_b", "m_h", "l", "m_P"])
def test_a_paper_length_or_mass_must_be_positive(name):
    with pytest.raises(ValueError, match=rf"^Params\.{name}: must be > 0, got 0\.0$"):
        Params.paper(**{name: 0.0, **({"l": 0.1} if name == "r" else {})})


@pytest.mark.parametrize("name", ["m_S", "j_S", "m_Y", "m_P"])
def test_a_general_mass_or_inertia_must_be_positive(name):
    with pytest.raises(ValueError, match=rf"^Params\.{name}: must be > 0, got 0\.0$"):
        Params(**{name: 0.0})


@pytest.mark.parametrize("name", ["k_S", "k_Y", "k_P", "g", "j_mY", "j_mP"])
def test_damping_gravity_and_rotors_must_not_be_negative(name):
    with pytest.raises(ValueError, match=rf"^Params\.{name}: must be >= 0, got -1e-09$"):
        Params(**{name: -1e-9})
    assert getattr(Params(**{name: 0.0}), name) == 0.0


@pytest.mark.parametrize("name", ["n_Y", "n_P"])
def test_a_gear_ratio_must_not_be_zero(name):
    with pytest.raises(ValueError, match=rf"^Params\.{name}: must be nonzero, got 0\.0$"):
        Params(**{name: 0.0})
    assert getattr(Params(**{name: -30.0}), name) == -30.0      # a reversing gear is fine


@pytest.mark.parametrize("J, why", [
    (np.diag([0.1, 0.2, 0.4]), "a principal moment above the sum of the other two"),
    (np.diag([-0.1, 0.2, 0.2]), "a negative moment"),
    ([[0.2, 0.18, 0], [0.18, 0.2, 0], [0, 0, 0.3]], "principal moments 0.38 > 0.02 + 0.3"),
])
def test_an_inertia_tensor_that_no_body_has_is_refused(J, why):
    with pytest.raises(ValueError, match=r"^Params\.J_P: not a physical inertia tensor"):
        Params(J_P=J)


def test_a_slender_rod_and_a_planar_body_are_physical():
    """The boundary cases of the triangle inequality: a zero moment, and J_zz = J_xx + J_yy."""
    Params(J_P=np.diag([0.01, 0.01, 0.0]), J_Y=np.diag([0.1, 0.3, 0.4]))


def test_an_asymmetric_tensor_is_refused_with_the_size_of_its_asymmetry():
    with pytest.raises(ValueError, match=r"^Params\.J_Y: an inertia tensor must be symmetric.*\|J - Jᵀ\| = 0\.01,"):
        Params(J_Y=[[0.2, 0.01, 0], [0.0, 0.3, 0], [0, 0, 0.4]])


def rotated_tensor():
    """R D Rᵀ for a rotation about a skew axis: symmetric only to rounding."""
    from runtime.so3 import exp
    R = exp(np.array([0.3, -0.7, 1.1]))
    return R @ np.diag([0.2, 0.3, 0.4]) @ R.T


def test_a_rotated_tensor_is_not_exactly_symmetric():
    """The premise of the next test: without it, that test could not fail."""
    J = rotated_tensor()
    assert not np.array_equal(J, J.T)


def test_a_tensor_symmetric_to_rounding_is_accepted_and_symmetrised():
    J = rotated_tensor()
    stored = np.array(Params(J_Y=J).J_Y)
    assert np.array_equal(stored, stored.T)
    assert np.abs(stored - J).max() <= 1e-15


def test_an_asymmetry_just_above_the_rounding_tolerance_is_refused():
    J = np.diag([0.2, 0.3, 0.4])
    J[0, 1] = 1e-11
    with pytest.raises(ValueError, match=r"^Params\.J_Y: an inertia tensor must be symmetric"):
        Params(J_Y=J)


@pytest.mark.parametrize("value", [[0.1, 0.2], "abc", [[0.1], [0.2], [0.3]]])
def test_a_centre_of_the_wrong_shape_is_named(value):
    with pytest.raises(ValueError, match=r"^Params\.c_Y: expected an array of real numbers of shape \(3,\)"):
        Params(c_Y=value)


@pytest.mark.parametrize("name", ["c_Y", "c_P"])
def test_a_centre_of_mass_outside_the_shell_is_refused(name):
    with pytest.raises(ValueError, match=rf"^Params\.{name}: the centre of mass must lie inside the shell .*r = 0\.3 m"):
        Params(**{name: (0.0, 0.3, 0.0)})
    Params(**{name: (0.0, 0.2999, 0.0)})


@pytest.mark.parametrize("slope", [math.pi / 2, -2.0])
def test_a_slope_beyond_a_right_angle_is_refused(slope):
    with pytest.raises(ValueError, match=r"^Params\.slope: the slope must lie strictly between -pi/2 and pi/2"):
        Params(slope=slope)


def test_the_yoke_must_fit_inside_the_shell():
    with pytest.raises(ValueError, match=r"^Params\.b, Params\.h: the yoke does not fit inside the shell .*"
                                         r"half-diagonal 0\.320156 m, r = 0\.3 m$"):
        Params.paper(b=0.4)
    Params.paper(b=0.33)      # half-diagonal 0.2996 m: fits


def test_the_pendulum_must_fit_inside_the_shell():
    with pytest.raises(ValueError, match=r"^Params\.l: the pendulum does not fit inside the shell .*l = 0\.31 m"):
        Params.paper(l=0.31)
    assert Params.paper(l=0.3).paper_params.l == 0.3      # touching the shell is allowed
    with pytest.raises(ValueError, match=r"^Params\.l"):
        Params.paper(l=0.3 * (1 + 1e-15))


def test_the_first_broken_rule_is_reported():
    with pytest.raises(ValueError, match=r"^Params\.k_S: must be finite"):
        Params.paper(m_S=-1.0, k_S=math.inf)


@pytest.mark.parametrize("value", [True, "0.3", None, 1j])
def test_a_value_that_is_not_a_real_number_is_named(value):
    with pytest.raises(ValueError, match=r"^Params\.r: expected a real number"):
        Params(r=value)
    with pytest.raises(ValueError, match=r"^Params\.r: expected a real number"):
        Params.paper(r=value)


def test_numpy_and_integer_values_become_floats():
    p = Params.paper(m_S=np.float32(2.5), m_h=5)
    assert type(p.m_S) is float and type(p.paper_params.m_h) is float and type(p.m_Y) is float


def test_params_accepts_exactly_what_the_c_model_accepts():
    """Random vectors around the boundaries: Params and sr_model_init agree on every one (one decider)."""
    rng = np.random.default_rng(3)
    base = Params().replace(c_Y=(0.01, 0.02, -0.01), J_P=np.diag([0.003, 0.002, 0.001]), j_mY=0.001,
                            slope=0.1).as_array()
    for _ in range(400):
        values = base * rng.choice([1.0, 0.0, -1.0, 1.9, 0.5], size=base.size, p=[0.8, 0.05, 0.05, 0.05, 0.05])
        try:
            Params.from_array(values)
            accepted = True
        except ValueError:
            accepted = False
        status = lib.sr_model_init(ffi.new("sr_model *"), ffi.new("double[]", list(values)))
        assert accepted == (status == lib.SR_OK), values


def test_paper_params_accepts_exactly_what_the_c_conversion_accepts():
    rng = np.random.default_rng(4)
    base = PaperParams().as_array()
    for _ in range(300):
        values = base * rng.choice([1.0, 0.0, -1.0, 1.9, 0.5], size=base.size, p=[0.8, 0.05, 0.05, 0.05, 0.05])
        try:
            PaperParams(**dict(zip(PAPER_NAMES, values)))
            accepted = True
        except ValueError:
            accepted = False
        status = lib.sr_paper_params(ffi.new("double[]", list(values)), ffi.new("double[]", lib.SR_NPARAM))
        assert accepted == (status == lib.SR_OK), values


@pytest.mark.parametrize("value", [np.zeros(3, dtype=complex), np.zeros(3, dtype=bool), ["0", "0", "0"]])
def test_a_centre_that_is_not_real_numbers_is_named(value):
    with pytest.raises(ValueError, match=r"^Params\.c_Y: expected an array of real numbers of shape \(3,\), got "):
        Params(c_Y=value)


def test_a_wrong_value_is_shown_on_one_line():
    with pytest.raises(ValueError) as info:
        Params(r=np.zeros((2, 1)))
    assert str(info.value) == "Params.r: expected a real number, got an array of shape (2, 1) (dtype float64)"
