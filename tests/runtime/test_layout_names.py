"""No module of runtime/ indexes a state by raw numbers: every one goes through the names of runtime/state.py.

The independent reference and the Kane model keep their own tables on purpose (checked against the
generated layout in tests/runtime/verification/test_tables.py) and are not scanned.
"""
import ast

from conftest import ROOT
from runtime import state

OWN_TABLES = {"runtime/verification/reference.py", "runtime/verification/alternatives/kane.py"}

#: Numbers that, in a subscript, can only mean a place in the state: block boundaries after the first
#: block, and every entry from q on (x[29] for q_z, x[33] for ω_Y, x[30:35] for ν, ...).
STATE_NUMBERS = ({idx.start for idx in state.ROTATION_BLOCKS.values()} - {0}) | set(range(state.IDX_Q.start, state.NX + 1))


def raw_state_subscripts(source):
    """(line, text) of every subscript whose index holds one of STATE_NUMBERS as a literal."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Subscript):
            literals = {n.value for n in ast.walk(node.slice) if isinstance(n, ast.Constant) and type(n.value) is int}
            if literals & STATE_NUMBERS:
                found.append((node.lineno, ast.unparse(node)))
    return found


def test_no_runtime_module_slices_a_state_by_number():
    offenders = []
    for path in sorted((ROOT / "runtime").rglob("*.py")):
        relative = path.relative_to(ROOT).as_posix()
        if relative not in OWN_TABLES:
            offenders += [f"{relative}:{line}: {text}" for line, text in raw_state_subscripts(path.read_text())]
    assert offenders == []


def test_the_scan_finds_raw_slices_and_leaves_named_ones():
    source = "a = x[27:30]\nb = x[..., 30:35]\nc = traj[:, 33]\nd = x[IDX_Q]\ne = calls[:5]\nf = x[0:9]\n"
    assert [line for line, _ in raw_state_subscripts(source)] == [1, 2, 3, 6]
