"""Sweep files (runtime/sweep/spec.py): validation, and the inputs of sample i."""
import re

import numpy as np
import pytest

from bindings._sr import lib
from runtime.state import IDX_QZ, IDX_UP, IDX_UY, pendulum_angle
from runtime.sweep.spec import load_sweep, quantity_values, sample_inputs, shipped_sweeps

from .conftest import SWEEP, write_sweep


def test_quantities_are_sorted_by_name(spec):
    assert [q.name for q in spec.quantities] == ["initial.theta_P", "params.k_S", "params.m_P", "torque.u_Y_scale"]


def test_random_draws_come_from_the_seed_and_the_sample_index_in_name_order(spec):
    values = quantity_values(spec, 0, spec.samples)
    for i in (0, 5, 23):
        rng = np.random.default_rng([7, i])
        assert values["params.k_S"][i] == rng.uniform(0.9, 1.1)
        assert values["params.m_P"][i] == rng.normal(1.0, 0.6)
        assert values["torque.u_Y_scale"][i] == rng.uniform(0.5, 1.5)


def test_grid_points_cycle_with_the_sample_index(spec):
    assert quantity_values(spec, 0, 6)["initial.theta_P"].tolist() == [0.0, 0.3] * 3


def test_a_sample_s_inputs_do_not_depend_on_the_chunk_it_is_in(spec):
    whole = quantity_values(spec, 0, 24)
    part = quantity_values(spec, 10, 15)
    for name in whole:
        assert np.array_equal(whole[name][10:15], part[name])


def test_inputs_apply_relative_factors_angles_and_torque_scales(spec):
    params, x0, u, values = sample_inputs(spec, 0, 4)
    base = spec.scenario
    k_S = lib.SR_P_k_S
    assert np.array_equal(params[:, k_S], values["params.k_S"] * base.params.k_S)
    assert np.array_equal(params[:, lib.SR_P_m_P], values["params.m_P"])
    assert np.allclose(pendulum_angle(x0), values["initial.theta_P"], atol=1e-15)
    assert np.array_equal(x0[:, IDX_QZ], params[:, lib.SR_P_r])
    program = base.torque_at_step_starts()
    assert u.shape == (4, base.steps, 2)
    assert np.array_equal(u[:, :, IDX_UY], values["torque.u_Y_scale"][:, None] * program[:, IDX_UY])
    assert np.array_equal(u[:, :, IDX_UP], np.broadcast_to(program[:, IDX_UP], (4, base.steps)))


@pytest.mark.parametrize("change, message", [
    (("samples = 24", "samples = 0"), "samples"),
    (("seed = 7", "seed = -1"), "seed"),
    (("[params.k_S]", "[params.k_X]"), "params: unknown key 'k_X'"),
    (("uniform = [0.9, 1.1]", "uniform = [1.1, 0.9]"), "params.k_S.uniform"),
    (("values = [0.0, 0.3]", "values = []"), "initial.theta_P.values"),
    (("normal = [1.0, 0.6]", "normal = [1.0, 0.6]\nuniform = [1, 2]"), "params.m_P: give exactly one"),
    (("relative = true", "relative = 1"), "params.k_S.relative"),
    (('scenario = "base.toml"', 'scenario = "nowhere.toml"'), "scenario"),
    (("[initial.theta_P]", "[initial.R_S]"), "initial: unknown key 'R_S'"),
    (("uniform = [0.9, 1.1]", "uniform = [-1e308, 1e308]"), "params.k_S.uniform: the width high - low"),
    (("normal = [1.0, 0.6]", "normal = [1.0, 1e307]"), "params.m_P.normal: |mean| + 100 sd"),
])
def test_bad_sweep_files_raise_value_errors_naming_the_key(tmp_path, change, message):
    path = write_sweep(tmp_path, SWEEP.replace(*change))
    with pytest.raises(ValueError, match=re.escape(message)):
        load_sweep(path)


def test_grid_values_must_make_valid_robots(tmp_path):
    path = write_sweep(tmp_path, SWEEP + "\n[params.r]\nvalues = [0.3, -1.0]\n")
    with pytest.raises(ValueError, match="params.r.values: -1 gives invalid parameters"):
        load_sweep(path)


def test_the_shipped_sweep_varies_every_mass_and_damping_by_ten_percent():
    assert "t-shape-uncertainty" in shipped_sweeps()
    spec = load_sweep("t-shape-uncertainty")
    assert spec.samples == 10_000 and spec.scenario.name == "t-shape"
    assert {q.name for q in spec.quantities} == {f"params.{n}" for n in ("m_S", "m_b", "m_h", "m_P", "k_S", "k_Y", "k_P")}
    assert all(q.kind == "uniform" and q.numbers == (0.9, 1.1) and q.relative for q in spec.quantities)


def test_samples_that_vary_no_torque_share_the_scenario_s_torque_program():
    """Parameters given by the paper's names must not be taken for torque factors: the shipped
    sweep once built a (samples, steps, 2) copy of one program per task (40 MB for 250 samples)."""
    spec = load_sweep("t-shape-uncertainty")
    params, x0, u, values = sample_inputs(spec, 0, 3)
    assert np.array_equal(u, spec.scenario.torque_at_step_starts())
