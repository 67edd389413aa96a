"""Benchmarks, `python -m runtime bench` (`make bench`): our kernels against the alternatives, side by side in one run.

Measured on one pinned core:
  C loop (bench/bench_kernels.c, no Python in the timed region): ns per accel
    (checked API and raw kernel), inertia, Lie–Euler step, fourth-order steps,
    and the CasADi-generated C of the independent reference model;
  from Python: ns per call of Model.accel, the NumPy transcription of the
    paper's formulas, the CasADi reference, the sympy.physics.mechanics
    (KanesMethod) model lambdified; batch accel over 10⁶ states, and for the
    alternatives over their own batch paths (CasADi's Function.map, the
    lambdified Kane model on arrays); the 10,000-step t-shape scenario end to
    end for every method, and for every alternative as the paper's Lie–Euler
    method in a Python loop around its accel.
Every alternative's numbers are compared with ours before its time is
reported; the bench exits non-zero only when a kernel gives wrong numbers.
Results: a table on stdout and JSON under bench/results/.

Modules: `cli` (the command), `harness` (the C loop: build, run, check),
`baselines` (the Python-side timings of ours and of the alternatives, and the
Lie–Euler loop a user of an alternative would write), `timing` (how a time is
taken), `checks` (numbers compared before a time counts), `report` (the table
and the result files).
"""
