"""Pointers into NumPy arrays for the C calls: the cast every wrapper in runtime/ makes."""
from ._sr import ffi


def pointer(array, kind="double"):
    """A `kind *` to `array`'s buffer, no copy: `array` must be C-contiguous of the matching dtype
    (float64 for double) and stay alive for as long as C may read or write through the pointer."""
    return ffi.cast(f"{kind} *", ffi.from_buffer(array))
