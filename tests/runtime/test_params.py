"""Params: its field order is the C library's (SR_P_*), and its validity is decided by C's sr_check_params."""
import math
import types

import numpy as np
import pytest

from bindings._sr import ffi, lib
from runtime import Params
from runtime.params import NAMES, parameter_order


def rule_text(rule):
    return ffi.string(lib.sr_param_rule_string(rule)).decode()


# -- order -----------------------------------------------------------------------------------------
def test_every_field_sits_at_its_c_index():
    assert len(NAMES) == lib.SR_NPARAM
    assert [getattr(lib, f"SR_P_{name}") for name in NAMES] == list(range(lib.SR_NPARAM))


def test_as_array_puts_each_value_at_its_c_index():
    p = Params(m_P=1.25, k_P=0.07)
    values = p.as_array()
    for name in NAMES:
        assert values[getattr(lib, f"SR_P_{name}")] == getattr(p, name)


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


# -- validity: the messages name the field and C's rule ------------------------------------------
@pytest.mark.parametrize("name", NAMES)
def test_a_non_finite_value_is_named(name):
    with pytest.raises(ValueError, match=rf"^Params\.{name}: {rule_text(lib.SR_PARAM_RULE_FINITE)}, got nan$"):
        Params(**{name: math.nan})


@pytest.mark.parametrize("name", ["r", "m_S", "b", "h", "m_b", "m_h", "l", "m_P"])
def test_a_length_or_mass_must_be_positive(name):
    with pytest.raises(ValueError, match=rf"^Params\.{name}: must be > 0, got 0\.0$"):
        Params(**{name: 0.0, **({"l": 0.1} if name == "r" else {})})


@pytest.mark.parametrize("name", ["k_S", "k_Y", "k_P", "g"])
def test_damping_and_gravity_must_not_be_negative(name):
    with pytest.raises(ValueError, match=rf"^Params\.{name}: must be >= 0, got -1e-09$"):
        Params(**{name: -1e-9})
    assert getattr(Params(**{name: 0.0}), name) == 0.0


def test_the_yoke_must_fit_inside_the_shell():
    with pytest.raises(ValueError, match=r"^Params\.b, Params\.h: the yoke does not fit inside the shell .*"
                                         r"half-diagonal 0\.320156 m, r = 0\.3 m$"):
        Params(b=0.4)
    Params(b=0.33)      # half-diagonal 0.2996 m: fits


def test_the_pendulum_must_fit_inside_the_shell():
    with pytest.raises(ValueError, match=r"^Params\.l: the pendulum does not fit inside the shell .*l = 0\.31 m"):
        Params(l=0.31)
    assert Params(l=0.3).l == 0.3      # touching the shell is allowed
    with pytest.raises(ValueError, match=r"^Params\.l"):
        Params(l=0.3 * (1 + 1e-15))


def test_the_first_broken_rule_is_reported():
    with pytest.raises(ValueError, match=r"^Params\.k_S: must be finite"):
        Params(m_S=-1.0, k_S=math.inf)


@pytest.mark.parametrize("value", [True, "0.3", None, 1j])
def test_a_value_that_is_not_a_real_number_is_named(value):
    with pytest.raises(ValueError, match=r"^Params\.r: expected a real number"):
        Params(r=value)


def test_numpy_and_integer_values_become_floats():
    p = Params(m_S=np.float32(2.5), m_h=5)
    assert type(p.m_S) is float and type(p.m_h) is float


def test_params_accepts_exactly_what_the_c_model_accepts():
    """Random vectors around the boundaries: Params and sr_model_init agree on every one (one decider)."""
    rng = np.random.default_rng(3)
    base = Params().as_array()
    for _ in range(400):
        values = base * rng.choice([1.0, 0.0, -1.0, 1.9, 0.5], size=base.size, p=[0.8, 0.05, 0.05, 0.05, 0.05])
        try:
            Params(**dict(zip(NAMES, values)))
            accepted = True
        except ValueError:
            accepted = False
        status = lib.sr_model_init(ffi.new("sr_model *"), ffi.new("double[]", list(values)))
        assert accepted == (status == lib.SR_OK), values
