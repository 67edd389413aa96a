"""The base parameters of the inertial parameters π: the identifiable combinations, for the table
of docs/identification.md (`python -m runtime base-parameters [--write]`).  The decomposition
itself is runtime.param_derivatives.base_parameters; this is the table and its command."""
import numpy as np

from ..atomic import write_text
from ..model import Model
from ..param_derivatives import NPI, base_parameters, inertial_parameters
from ..params import Params


#: The robots of the base-parameter table in docs/identification.md: (label, parameters).
def table_robots():
    """The paper's robot as simulated, and a general robot with a geared yoke motor (n_Y = 60)."""
    paper = Params.paper_simulation()
    geared = paper.replace(j_mY=2e-5, n_Y=60.0, j_mP=1e-5, n_P=30.0,
                           c_Y=np.array([0.002, -0.001, 0.003]), J_Y=np.asarray(paper.J_Y) + np.diag([1e-4, 0.0, 0.0]))
    return (("the paper's robot (Params.paper_simulation())", paper),
            ("a general robot, geared motors (n_Y = 60, n_P = 30), off-centre yoke", geared))


TABLE_BEGIN, TABLE_END = "<!-- base-parameters: python -m runtime base-parameters --write -->", "<!-- /base-parameters -->"


def base_parameter_table(n_states=60, seed=0, rtol=1e-9):
    """The base parameters of `table_robots` as Markdown: for each robot its rank and each
    identifiable combination with its value (values below 1e-12 of the largest, rounding of
    zeros, printed as 0)."""
    lines = []
    for label, params in table_robots():
        base = base_parameters(Model(params), n_states, seed, rtol)
        values = base.values(inertial_parameters(params))
        values[np.abs(values) < 1e-12 * np.abs(values).max()] = 0.0
        s = base.singular_values
        lines += [f"**{label}**: rank {base.rank} of {NPI}; the singular values of the column-scaled regressor "
                  f"run from {s[0]:.3g} to {s[base.rank - 1]:.3g}, the next {NPI - base.rank} are below "
                  f"{rtol:g} of the largest.", "",
                  "| base parameter | value |", "|---|---|"]
        lines += [f"| `{name}` | {value:.6g} |" for name, value in zip(base.names(4), values)]
        lines.append("")
    return "\n".join(lines).rstrip() + "\n"


def main(argv):
    """`python -m runtime base-parameters [--write]`: print the base-parameter table, or with --write
    rewrite its block in docs/identification.md."""
    import argparse
    import pathlib
    parser = argparse.ArgumentParser(prog="python -m runtime base-parameters", description=main.__doc__)
    parser.add_argument("--write", action="store_true", help="rewrite the table's block in docs/identification.md")
    args = parser.parse_args(argv)
    table = base_parameter_table()
    if not args.write:
        print(table, end="")
        return 0
    path = pathlib.Path(__file__).resolve().parents[2] / "docs" / "identification.md"
    text = path.read_text()
    head, rest = text.split(TABLE_BEGIN, 1)
    _, tail = rest.split(TABLE_END, 1)
    write_text(path, head + TABLE_BEGIN + "\n" + table + TABLE_END + tail)
    return 0
