"""Sweeps: many runs of one scenario with varied parameters, initial states and torques, on Dask.

spec.py (sweep files, the inputs of sample i), task.py (one task: a chunk of samples in one C
batch call), store.py (the output folder, chunk by chunk, resumable, every chunk verified before
it is merged), runner.py (Dask or serial), summary.py (figure, percentile table), cli.py
(`python -m runtime sweep`).
Shipped sweep files live next to these modules (*.toml).
"""
