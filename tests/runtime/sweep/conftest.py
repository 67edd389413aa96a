"""A small sweep for the tests: 24 samples of a 400-step run, a grid, random parameters (some
invalid: those samples fail alone), random torque programs."""
import textwrap

import pytest

from runtime.sweep.spec import load_sweep

BASE = """
description = "short t-shape-like run"
dt = 0.01
steps = 400
method = "lie-euler"
[params]
preset = "paper_simulation"
[[torque]]
from_step = 1
to_step = 150
u_Y = 0.1
[[torque]]
from_step = 200
to_step = 300
u_P = -0.1
"""

SWEEP = """
description = "test sweep"
scenario = "base.toml"
samples = 24
seed = 7
samples_per_task = 5
[params.m_P]
normal = [1.0, 0.6]          # about 5 % of the draws are negative: SR_ERR_PARAM
[params.k_S]
uniform = [0.9, 1.1]
relative = true
[initial.theta_P]
values = [0.0, 0.3]
[torque.u_Y_scale]
uniform = [0.5, 1.5]
"""


def write_sweep(folder, text=SWEEP, name="small"):
    (folder / "base.toml").write_text(textwrap.dedent(BASE))
    path = folder / f"{name}.toml"
    path.write_text(textwrap.dedent(text))
    return path


@pytest.fixture
def sweep_file(tmp_path):
    return write_sweep(tmp_path)


@pytest.fixture
def spec(sweep_file):
    return load_sweep(sweep_file)
