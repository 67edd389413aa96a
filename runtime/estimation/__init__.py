"""Estimation: sensor logs (`logs`: the log schema, `write_log`, `read_log`) and simulated logs
(`sense`: `python -m runtime sense`); docs/estimation.md."""
