"""`python -m runtime COMMAND [options]`: the one command-line entry of runtime/; one module per command,
each with its own `main(argv) -> int` (no module of runtime/ runs as a script of its own)."""
import importlib
import sys

COMMANDS = {
    "run": ("runtime.scenarios.cli", "run a shipped scenario, a scenario file, or `all`"),
    "view": ("runtime.scenarios.view", "open the interactive replay of a run (e.g. out/t-shape) in the browser"),
    "verify": ("runtime.verification.verify", "cross-check the kernels against the reference and the invariants"),
    "convergence": ("runtime.verification.convergence", "convergence and energy study of the integrators"),
    "bench": ("runtime.bench.cli", "benchmarks against the alternatives"),
    "bench-table": ("runtime.bench.headline", "the benchmark tables of README.md and docs/performance.md, from the pinned run"),
    "figures": ("runtime.scenarios.figures", "regenerate the committed figures under docs/figures/"),
    "sweep": ("runtime.sweep.cli", "many runs of a scenario with varied inputs, on Dask (results in Parquet)"),
    "control": ("runtime.control.benchmark", "closed-loop benchmark: every controller on every task (make control)"),
    "export": ("runtime.interop.export", "the robot for other tools: `export fmu` (FMI 2.0, 3.0; make fmu), `export mjcf` (MuJoCo)"),
    "compare-mujoco": ("runtime.interop.mujoco_compare", "a scenario in the kernels and in MuJoCo (the exported MJCF), their differences"),
    "soak": ("runtime.verification.soak", "10^7 steps from random states: constraint and energy drift (not a unit test)"),
    "errata": ("runtime.verification.errata", "the paper's printed formulas against the kernels (docs/errata.md)"),
    "stability": ("runtime.stability", "eigenvalues and Floquet exponents; writes docs/figures/rolling-stability.png"),
    "envelope": ("runtime.control.envelope", "what the torque limits allow (make envelope)"),
    "noise-floor": ("runtime.control.noise_floor", "the LQR's steady wander under a sensor set's process noise, and its floor"),
    "heading-seeds": ("runtime.control.heading_seeds", "the heading step on the robot's own filter over noise seeds: runs within the deadline, misses by class"),
    "climbing": ("runtime.control.climbing", "the climbing limit on a slope; writes docs/figures/climbing-limit.png"),
    "nmpc-c": ("runtime.control.nmpc_c", "the C NMPC: its design as C, its timing in a C loop, its QPs against DAQP"),
    "firmware-table": ("runtime.control.firmware", "the firmware examples' LQR gain table, generated/lqr_task.h, and the estimator example's vector (make generate)"),
    "sweep-bench": ("runtime.bench.sweep", "what a sweep costs (make sweep-bench)"),
    "sense": ("runtime.estimation.sense", "simulate the sensors along a scenario or task: a log and its truth"),
    "estimate": ("runtime.estimation.estimate", "run the EKF over a sensor log: the estimate, its sigmas, the errors"),
    "consistency": ("runtime.estimation.consistency", "Monte Carlo consistency of the EKF (NEES, 3 sigma) over seeded runs, on Dask"),
    "surrogate": ("runtime.estimation.surrogate", "the linear-Gaussian surrogate of a consistency run: the in-band share's spread for a consistent filter"),
    "estimation-figures": ("runtime.estimation.figures", "regenerate docs/estimation.md's frames and estimate figures"),
    "base-parameters": ("runtime.identification.base_parameters", "the identifiable combinations of the inertial parameters (docs/identification.md)"),
    "excite": ("runtime.identification.excite", "a D-optimal torque program for identifying named parameters, as a scenario"),
    "identify": ("runtime.identification.identify", "fit a robot's parameters to a log: estimates, intervals, identifiability, a robot file"),
    "identify-coverage": ("runtime.identification.coverage", "seeded fits: how often the 95 % intervals hold the truth"),
    "identify-bench": ("runtime.identification.bench", "the same fit with analytic and with finite-difference sensitivities: times, ratio, optima"),
}


def usage():
    lines = ["usage: python -m runtime COMMAND [options]", "", "commands:"]
    lines += [f"  {name:<15} {doc}" for name, (_, doc) in COMMANDS.items()]
    return "\n".join(lines)


def main(argv):
    if not argv or argv[0] in ("-h", "--help") or argv[0] not in COMMANDS:
        print(usage(), file=sys.stderr if argv and argv[0] not in ("-h", "--help") else sys.stdout)
        return 0 if argv and argv[0] in ("-h", "--help") else 2
    module = importlib.import_module(COMMANDS[argv[0]][0])
    return module.main(argv[1:])


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
