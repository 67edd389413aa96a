"""Every public entry point of the Python API, given wrong input of every kind (wrong type, dtype,
shape, NaN/inf, overflow-size numbers, empty batches, unknown names): a ValueError naming the
argument, or a finite result (tests/wrong_inputs.py, docs/robustness.md)."""
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from wrong_inputs import SETTINGS, all_finite, keeps_contract, wrong_array, wrong_name, wrong_scalar

from runtime import Model, Params, initial_state, simulate_many
from runtime import casadi_model

MODEL = Model(Params.paper_simulation())
X = initial_state(theta_Y=0.2, theta_P=0.4, w_S=[0.1, -0.2, 0.3], r=MODEL.params.r)
U = np.array([0.1, -0.1])
D = np.linspace(-0.1, 0.1, 12)

#: Each entry point: (callable of the keyword arguments, the valid arguments, which are arrays).
ENTRY_POINTS = {
    "accel": (MODEL.accel, {"x": X, "u": U}),
    "inertia": (MODEL.inertia, {"x": X}),
    "rhs": (MODEL.rhs, {"x": X, "u": U}),
    "energy": (MODEL.energy, {"x": X}),
    "contact_force": (MODEL.contact_force, {"x": X, "u": U}),
    "equilibrium_residual": (MODEL.equilibrium_residual, {"x": X}),
    "project": (MODEL.project, {"x": X}),
    "step": (MODEL.step, {"x": X, "u": U, "dt": 0.01, "method": "rkmk4"}),
    "simulate": (MODEL.simulate, {"x0": X, "dt": 0.01, "steps": 3, "u": np.tile(U, (3, 1)), "method": "cf4"}),
    "simulate_adaptive": (MODEL.simulate_adaptive, {"x0": X, "t_end": 0.02, "dt_out": 0.01,
                                                    "u": np.tile(U, (2, 1)), "method": "rkmk4"}),
    "retract": (MODEL.retract, {"x": X, "d": D}),
    "local": (MODEL.local, {"x": X, "y": MODEL.retract(X, D)}),
    "accel_jacobian": (MODEL.accel_jacobian, {"x": X, "u": U}),
    "linearize": (MODEL.linearize, {"x": X, "u": U}),
    "step_jacobian": (MODEL.step_jacobian, {"x": X, "u": U, "dt": 0.01, "method": "cf4"}),
    # A sample that fails has its status and NaN rows (documented); those that succeed must be finite.
    "simulate_many": (lambda **kw: (lambda res: res.final[res.status == 0])(simulate_many(**kw)),
                      {"params": MODEL.params, "x0": X, "dt": 0.01, "steps": 3, "method": "lie-euler"}),
}
NAMED = {"method"}
SCALARS = {"dt", "steps", "t_end", "dt_out"}
CASES = [(entry, arg) for entry, (_, args) in ENTRY_POINTS.items() for arg in args if arg != "params"]


@st.composite
def wrong_value(draw, arg, valid):
    if arg in NAMED:
        return wrong_name(draw)
    if arg in SCALARS:
        return wrong_scalar(draw, allow_zero=arg == "t_end")
    return wrong_array(valid, draw)


@pytest.mark.parametrize("entry, arg", CASES, ids=[f"{e}-{a}" for e, a in CASES])
@SETTINGS
@given(data=st.data())
def test_a_wrong_argument_gives_a_value_error_naming_it_or_a_finite_result(entry, arg, data):
    call, args = ENTRY_POINTS[entry]
    kind, value = data.draw(wrong_value(arg, args[arg]))
    # An overflow-size number is valid input to some arguments; the result then overflows, and
    # the error names the result's inputs, or the running state x of a simulation that stops
    # (SimulationStopped, documented).  Every other kind must name the argument itself.
    names = list(args) + ["x"] if kind == "huge" else [arg]
    if entry == "simulate_many" and kind in ("nonfinite", "huge") and arg == "x0":
        # A bad sample's values are the sample's status (documented), not an exception.
        result = simulate_many(**{**args, arg: value})
        assert result.status[0] != 0 or all_finite(result.final)
        return
    keeps_contract(lambda: call(**{**args, arg: value}), kind, names)


BATCHED = {"accel": ("x", "u"), "contact_force": ("x", "u"), "inertia": ("x",), "rhs": ("x", "u"), "energy": ("x",),
           "equilibrium_residual": ("x",), "project": ("x",), "step": ("x", "u"), "retract": ("x", "d"),
           "local": ("x", "y"), "accel_jacobian": ("x", "u"), "linearize": ("x", "u"),
           "step_jacobian": ("x", "u")}


@pytest.mark.parametrize("entry", sorted(BATCHED))
def test_an_empty_batch_gives_empty_results_or_a_named_error(entry):
    call, args = ENTRY_POINTS[entry]
    empty = {**args, **{a: np.empty((0,) + np.shape(args[a])) for a in BATCHED[entry]}}
    result = keeps_contract(lambda: call(**empty), "empty", list(BATCHED[entry]))
    if result is not None:
        for out in result if isinstance(result, tuple) else (result,):
            assert np.shape(out)[0] == 0


def test_linearize_and_accel_jacobian_agree_on_an_empty_batch():
    A, B = MODEL.linearize(np.empty((0, 35)))
    Ja, Jb = MODEL.accel_jacobian(np.empty((0, 35)))
    assert A.shape == (0, 12, 12) and B.shape == (0, 12, 2) and Ja.shape == (0, 5, 12) and Jb.shape == (0, 5, 2)


@pytest.mark.parametrize("method", [["rkmk4"], None, 1, {"rkmk4": 1}])
@pytest.mark.parametrize("entry", ["step", "step_jacobian", "simulate", "simulate_adaptive", "simulate_many"])
def test_a_method_that_is_not_a_name_is_refused_naming_method(entry, method):
    call, args = ENTRY_POINTS[entry]
    with pytest.raises(ValueError, match=r"^method: unknown integrator"):
        call(**{**args, "method": method})


def test_retract_with_an_overflowing_d_names_d():
    d = D.copy()
    d[5] = 1.7e308
    x = X.copy()
    x[27] = 1e308
    with pytest.raises(ValueError, match=r"^d: x ⊕ d overflows"):
        MODEL.retract(x, d)


def test_local_with_an_overflowing_difference_names_y():
    x, y = X.copy(), X.copy()
    x[27], y[27] = -1.7e308, 1.7e308
    with pytest.raises(ValueError, match=r"^y: y ⊖ x overflows"):
        MODEL.local(x, y)


@SETTINGS
@given(field=st.sampled_from(["r", "m_S", "j_S", "m_Y", "c_Y", "J_Y", "m_P", "c_P", "J_P", "k_Y", "g", "slope"]),
       data=st.data())
def test_a_wrong_parameter_gives_a_value_error_naming_it(field, data):
    valid = np.asarray(getattr(Params(), field))
    kind, value = wrong_array(valid, data.draw)
    result = keeps_contract(lambda: Params(**{field: value}), kind, [f"Params.{field}"])
    if result is not None:       # an overflow-size value passed the rules one by one: C's check of the model
        keeps_contract(lambda: Model(result), kind, ["params"])


@pytest.mark.parametrize("scale, field", [(1e300, "J_Y"), (1e300, "m_S")])
def test_a_model_refused_for_its_scale_names_the_extreme_parameter(scale, field):
    params = Params(**{field: scale * np.asarray(getattr(Params(), field))})
    with pytest.raises(ValueError, match=rf"^params: .*the most extreme value is Params\.{field}\b"):
        Model(params)


def test_a_model_of_huge_inertias_is_not_said_to_underflow():
    with pytest.raises(ValueError) as info:
        Model(Params(J_Y=1e300 * np.eye(3)))
    assert "overflow" in str(info.value)


@SETTINGS
@given(params=st.sampled_from(["abc", None, 1.0, {"r": 0.3}, [Params()], np.zeros(3)]))
def test_a_model_of_something_else_than_params_names_params(params):
    if params is None:
        return                            # None is the default robot
    keeps_contract(lambda: Model(params), "type", ["params"])


@SETTINGS
@given(data=st.data())
def test_casadi_model_load_names_the_function_argument(data):
    kind, name = wrong_name(data.draw)
    keeps_contract(lambda: casadi_model.load(name), kind, ["name"])


def test_paper_params_is_part_of_the_api():
    import runtime
    assert runtime.PaperParams().robot() == Params.paper()
