"""The scenario application: the shipped scenario files (the *.toml here; their format, loading and
running are the core's runtime/scenario.py), the `python -m runtime run` command (`cli`), the outputs
of a run (`report`: CSV, summary, the set of files; `plots`: the figures; `animation`: the GIF;
`replay`: the interactive page) and the committed figures (`figures`)."""
