"""The one checker of TOML tables: scenario, task and sweep files all reject a key they do not
know, naming the file and table it is in and the keys allowed there (a misspelt key would
otherwise be ignored silently, and the run would use the default); and keeps every number of
them inside a fixed, documented range (`Range`: what is physical and what is computable), so that a
value that would hang a run or exhaust the memory is refused when the file loads.
docs/robustness.md lists the ranges, generated from the files' tables."""
import dataclasses
import math


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


# -- ranges ----------------------------------------------------------------------------------
@dataclasses.dataclass(frozen=True)
class Range:
    """The interval a number of a file may take: [low, high] (low excluded with `open_low`), a
    whole number with `whole`; `unit` and `why` (what makes it physical or computable) are
    shown in the message and in docs/robustness.md."""
    low: float
    high: float
    unit: str = ""
    why: str = ""
    whole: bool = False
    open_low: bool = False

    def __str__(self):
        text = f"{'(' if self.open_low else '['}{_number(self.low)}, {_number(self.high)}]"
        return f"{'a whole number' if self.whole else 'a number'} in {text} {self.unit}".rstrip()

    def contains(self, value):
        """Whether the number `value` lies in the range (and is whole, if it must be)."""
        inside = (self.low < value if self.open_low else self.low <= value) and value <= self.high
        return inside and (not self.whole or float(value).is_integer())


def _number(value):
    if float(value).is_integer() and abs(value) < 1e7 or isinstance(value, int):
        return str(int(value))
    text = f"{value:g}"
    return text if float(text) == value else repr(float(value))


def check_range(value, rng, where):
    """`value` if it is a number inside `rng`; otherwise ValueError("<where>: ...") giving the range.
    Values that are not finite numbers are left to the caller's type checks (returned as they are)."""
    if not _is_number(value) or not math.isfinite(value):
        return value
    if not rng.contains(value):
        why = f" ({rng.why})" if rng.why else ""
        raise ValueError(f"{where}: expected {rng}, got {value!r}{why}")
    return value


def check_arguments(values, ranges):
    """The arguments of a constructor ({name: value}) with a range in `ranges` ({name: Range}): each a
    finite real number (not a bool) inside its range; otherwise ValueError("<name>: ...") naming the
    argument and giving its range, as a file's key would."""
    for name, value in values.items():
        rng = ranges.get(name)
        if rng is None:
            continue
        if not _is_number(value) and not (hasattr(value, "dtype") and getattr(value, "shape", None) == ()
                                          and value.dtype.kind in "iuf"):
            raise ValueError(f"{name}: expected {rng}, got {show(value)}")
        if not math.isfinite(value):
            raise ValueError(f"{name}: expected {rng}, got {value!r}")
        check_range(value, rng, name)
    return values


def check_ranges(table, ranges, where, sep="."):
    """Every number of `table` (a dict) under a key of `ranges` ({key: Range}) checked by
    `check_range`, lists and lists of lists entry by entry (`<where>.<key>[i][j]`); `table`
    itself (`sep` joins `where` and a key: ": " after a file's name).  Keys without a range and values that are not numbers are left to the caller."""
    if not isinstance(table, dict):
        return table
    for key, rng in ranges.items():
        if key in table:
            _check_nested(table[key], rng, f"{where}{sep}{key}" if where else key)
    return table


def _check_nested(value, rng, where):
    if isinstance(value, list):
        for i, item in enumerate(value):
            _check_nested(item, rng, f"{where}[{i}]")
    else:
        check_range(value, rng, where)


def _is_number(value):
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def ranges_markdown(sections):
    """A Markdown table of {section: {key: Range}}: the ranges of one file kind, as
    docs/robustness.md lists them."""
    lines = ["| key | range | why |", "|---|---|---|"]
    for section, ranges in sections.items():
        for key, rng in ranges.items():
            name = f"{section}.{key}" if section else key
            lines.append(f"| `{name}` | {rng} | {rng.why} |")
    return "\n".join(lines)
