"""Benchmarks, `python -m runtime bench` (`make bench`): our kernels against the alternatives, like
against like, every alternative's numbers checked against ours before its time counts.

C against C (bench/bench_kernels.c, no Python in the timed region, one pinned core): our checked
  accel, the raw generated kernel, inertia, one step of every integrator; the Kane model
  (sympy.physics.mechanics) compiled the ways its users ship it: CasADi's C of M and F with
  ca.solve, SymPy's C printer with a generic LU, PyDy's C with the same LU
  (`kane_compiled`); and the CasADi C of our own 9x9 KKT reference, a verification model.
The anatomy of a fourth-order step (bench/step_anatomy.c): the checked accel, four accels
  chained as a step's stages chain them, the RKMK4 and CF4 steps, and the same steps with the
  dynamics replaced by a stub (everything but the four accelerations).
Python call against Python call: Model.accel and Model.step against the raw cffi call of the
  checked C function with prepared buffers, PyDy's Cython ODE function, the lambdified
  Kane model (three ways), a CasADi Function call of the Kane model, the CasADi reference and the
  NumPy transcription of the paper's formulas.
Batches (Model.accel over 10⁶ states, CasADi's Function.map, the lambdified Kane model on
  arrays) and the 10,000-step t-shape scenario end to end, for every method, and for every
  alternative as the paper's Lie–Euler method in a Python loop around its accel.
The bench exits non-zero only when a kernel or a baseline gives wrong numbers.  Results: a table
on stdout, with the CPU, and one JSON per run under bench/results/ (`<date and time>.json`,
never overwritten).

Modules: `cli` (the command), `harness` (the C loop: build, run, check), `kane_compiled` (the
Kane model as C and as compiled Python calls), `baselines` (the Python-side timings of ours and
of the alternatives, and the Lie–Euler loop a user of an alternative would write), `timing` (how
a time is taken), `checks` (numbers compared before a time counts), `report` (the table, the
targets and the result file), `sweep` (`python -m runtime sweep-bench`: what a sweep costs on Dask).
"""
