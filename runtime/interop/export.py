"""`python -m runtime export KIND [options]`: the robot for another tool, one module per kind
(`export fmu`: FMI 2.0 and 3.0 co-simulation FMUs, runtime/interop/fmu.py; `export mjcf`: a MuJoCo
model, runtime/interop/mjcf.py)."""
import importlib
import sys

KINDS = {
    "fmu": ("runtime.interop.fmu", "FMI 2.0 and 3.0 co-simulation FMUs (make fmu)"),
    "mjcf": ("runtime.interop.mjcf", "a MuJoCo model (MJCF) of the robot"),
}
"""kind -> (the module whose `main` writes it, what it is)."""


def usage():
    """The usage text: the kinds and what each writes."""
    lines = ["usage: python -m runtime export KIND [options]", "", "kinds:"]
    lines += [f"  {name:<6} {doc}" for name, (_, doc) in KINDS.items()]
    return "\n".join(lines)


def main(argv):
    """Dispatch to the kind's `main`; status 2 with the usage for a missing or unknown kind."""
    if argv and argv[0] in ("-h", "--help"):
        print(usage())
        return 0
    if not argv or argv[0] not in KINDS:
        print(usage(), file=sys.stderr)
        print(f"export: unknown kind {argv[0]!r}; choose one of {', '.join(KINDS)}" if argv
              else f"export: give a kind: {', '.join(KINDS)}", file=sys.stderr)
        return 2
    return importlib.import_module(KINDS[argv[0]][0]).main(argv[1:])
