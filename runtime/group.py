"""The state as a point of SO(3) × SO(2) × SO(2) × ℝ² × ℝ⁵ and its error coordinates.

`x ⊕ d` (retract) and `y ⊖ x` (local) in the right-trivialised coordinates of
`runtime.state.NE` (c/spherical_robot.h, c/sr_group.c): the contract in which the Jacobians of
the dynamics and of the steps are expressed.  `Model` inherits these methods; loops run in C.
"""
import numpy as np

from bindings._sr import ffi, lib
from bindings.buffers import pointer

from .errors import KernelError
from .state import NE, NX
from .validation import check_finite, real_array



class GroupMethods:
    """`retract` and `local` of `Model` (which provides _model, _valid_states and _check)."""

    def retract(self, x, d):
        """x ⊕ d: state(s) (35,) / (B, 35) moved by error(s) d (12,) / (B, 12) (exact for every angle)."""
        x = self._valid_states(x)
        d = real_array(d, "d", (NE,))
        if d.shape[:-1] != x.shape[:-1]:
            raise ValueError(f"d: shape {d.shape} does not match x of shape {x.shape}")
        check_finite(d, "d")
        return self._group_call(lib.sr_retract, lib.sr_retract_batch, x, d, NX, "d", "x ⊕ d")

    def local(self, x, y):
        """y ⊖ x: the error(s) d (12,) / (B, 12) with x ⊕ d = y (|ξ_S| ≤ π, joint angles in (−π, π])."""
        x = self._valid_states(x)
        y = self._valid_states(y, "y")
        if y.shape != x.shape:
            raise ValueError(f"y: shape {y.shape} does not match x of shape {x.shape}")
        return self._group_call(lib.sr_local, lib.sr_local_batch, x, y, NE, "y", "y ⊖ x")

    def _group_call(self, single, batch, x, other, width, name, result):
        # Both arguments were checked (x valid, `other` finite): a non-finite result can only be
        # an overflow of x's entries by `other`'s, and that is `other`'s fault.
        if x.ndim == 1:
            out = np.empty(width)
            self._blame(name, result, single(self._model, pointer(x), pointer(other), pointer(out)))
            return out
        out = np.empty((x.shape[0], width))
        failed = ffi.new("long *")
        status = batch(self._model, x.shape[0], pointer(x), pointer(other), pointer(out), failed)
        self._blame(f"{name}[{failed[0]}]" if failed[0] >= 0 else name, result, status)
        return out

    def _blame(self, name, result, status):
        if status == lib.SR_ERR_NONFINITE:
            raise KernelError(name, status, message=f"{name}: {result} overflows (is not finite): {name} "
                                                    f"is too large for this state")
        self._check("x", status)
