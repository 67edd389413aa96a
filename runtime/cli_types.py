"""argparse types the commands share: each refuses a wrong value with one line saying what it
expected (argparse puts the option's name in front)."""
import argparse
import math


def whole_number(low=0):
    """A type for a whole number >= low."""
    def parse(value):
        if not value.isdigit() or int(value) < low:
            raise argparse.ArgumentTypeError(f"expected a whole number >= {low}, got {value!r}")
        return int(value)
    return parse


def _finite_positive(value, expected):
    try:
        number = float(value)
    except ValueError:
        number = math.nan
    if not (math.isfinite(number) and number > 0):
        raise argparse.ArgumentTypeError(f"expected {expected}, got {value!r}")
    return number


def positive_number(value):
    """A type for a finite number > 0."""
    return _finite_positive(value, "a number > 0")


def duration(value):
    """A type for a finite duration > 0 in s."""
    return _finite_positive(value, "a duration > 0 in s")
