"""The one checker of TOML tables: scenario, task and sweep files all reject a key they do not
know, naming the file and table it is in and the keys allowed there (a misspelt key would
otherwise be ignored silently, and the run would use the default)."""


def show(value):
    """`value` for an error message: its type and a repr cut to 60 characters."""
    text = repr(value)
    return f"{type(value).__name__} {text if len(text) <= 60 else text[:57] + '...'}"


def check_table(table, allowed, where):
    """`table` itself if it is a table (dict) whose keys are all in `allowed`; otherwise
    ValueError("<where>: ...") saying what it is instead, or which keys are unknown and which are allowed."""
    if not isinstance(table, dict):
        raise ValueError(f"{where}: expected a table, got {show(table)}")
    allowed = set(allowed)
    unknown = sorted(set(table) - allowed)
    if unknown:
        raise ValueError(f"{where}: unknown key{'s' if len(unknown) > 1 else ''} "
                         f"{', '.join(map(repr, unknown))}; allowed: {', '.join(sorted(allowed))}")
    return table
