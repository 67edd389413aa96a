"""The scenario application: scenario files (the *.toml here), loading and running them (`scenario`),
the `python -m runtime run` command (`cli`), the outputs of a run (`report`: CSV, summary, the set of
files; `plots`: the figures; `animation`: the GIF; `atomic`: atomic writing) and the committed figures
(`figures`)."""
