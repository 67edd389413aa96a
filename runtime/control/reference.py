"""References a controller tracks: a speed, a heading, or a path (line, circle, figure eight, waypoints).

Every reference answers one question, `target(t, position, heading)` -> `Target`: the speed to
hold, the heading to hold (speed and heading tasks) or the path's local geometry (path tasks:
the nearest point's tangent heading, curvature and the signed cross-track error, positive when
the robot is to the left of the path).  Paths are built once from the start pose as polylines
sampled every `PATH_DS` m and searched near the last match, so that a figure eight's crossing
does not make the nearest point jump to the other lobe.
"""
import dataclasses
import math

import numpy as np

from .geometry import wrap_angle

#: Kinds of `[reference]` in task files.
KINDS = ("speed", "heading", "line", "circle", "figure8", "waypoints")
#: Path sampling step [m] and the arc length searched around the last nearest point [m].
PATH_DS = 0.005
SEARCH_BACK_M, SEARCH_AHEAD_M = 0.5, 1.5


@dataclasses.dataclass(frozen=True)
class Target:
    """What a controller tracks at one sample: speed, heading and, for paths, curvature and cross-track
    error."""
    speed: float                      # m/s
    heading: float                    # rad: the heading to hold, or the path's tangent heading
    curvature: float = 0.0            # 1/m, left positive (path tasks)
    cross_track: float | None = None  # m, positive when the robot is left of the path (path tasks)
    curvature_ahead: tuple | None = None  # 1/m at the distances a controller asked for (its preview)


class SpeedHeading:
    """Hold `speed` [m/s] and `heading` [rad] (both constant from t = 0)."""
    is_path = False

    def __init__(self, speed, heading):
        self.speed, self.heading = float(speed), float(heading)

    def target(self, t, position, heading):
        """The constant speed and heading, whatever the time and position."""
        return Target(self.speed, self.heading)


#: A turn between samples below this [rad] is straight (round-off of collinear samples).
STRAIGHT_RAD = 1e-9


def _spread_curvature(s, turns):
    """The curvature (n,) [1/m] at the samples of arc lengths s (n,) of a path turning by `turns`
    (n − 2,) [rad] at its interior samples: each turn spread evenly over the arc length centred on
    its sample and reaching halfway to the nearest turning sample (or end) on either side, as a fillet
    would round it; then each sample's curvature the mean over its own cell (halfway to its
    neighbours).  A path that turns at every sample (a sampled arc) keeps turn / cell; a polyline
    sampled finer than its legs turns at few samples, and a point curvature there (turn / cell,
    tens of times the legs' mean) would be all that a controller sampling the path ahead sees or
    misses: its mean curvature is the turn spread over the legs."""
    n = len(s)
    kappa = np.zeros(n)
    at = 1 + np.nonzero(np.abs(turns) > STRAIGHT_RAD)[0]
    if len(at) == 0:
        return kappa
    bounds = np.concatenate([[0], at, [n - 1]])
    half = 0.5 * np.minimum(s[at] - s[bounds[:-2]], s[bounds[2:]] - s[at])
    # The cumulative turn Θ(s): a ramp of each turn over its window (windows touch at most).
    knots = np.ravel(np.column_stack([s[at] - half, s[at] + half]))
    theta = np.concatenate([[0.0], np.repeat(np.cumsum(turns[at - 1]), 2)[:-1]])
    lo = np.concatenate([[s[0]], 0.5 * (s[:-1] + s[1:])])
    hi = np.concatenate([0.5 * (s[:-1] + s[1:]), [s[-1]]])
    kappa[1:-1] = ((np.interp(hi, knots, theta) - np.interp(lo, knots, theta)) / (hi - lo))[1:-1]
    return kappa


class Path:
    """A path sampled as points (n, 2), with tangent headings and curvatures per point, at `speed`."""
    is_path = True

    def __init__(self, points, speed):
        self.points = np.asarray(points, dtype=np.float64)
        d = np.diff(self.points, axis=0)
        seg = np.hypot(d[:, 0], d[:, 1])
        if np.any(seg <= 0):
            raise ValueError("reference: the path repeats a point")
        self.s = np.concatenate([[0.0], np.cumsum(seg)])
        self.tangent = np.concatenate([np.arctan2(d[:, 1], d[:, 0]), [math.atan2(d[-1, 1], d[-1, 0])]])
        turn = wrap_angle(np.diff(self.tangent))
        # A polyline's corners (turns > 0.1 rad between samples) are not curvature to feed forward.
        self.curvature = _spread_curvature(self.s, np.where(np.abs(turn[:-1]) > 0.1, 0.0, turn[:-1]))
        self.speed = float(speed)
        self._hint = 0

    def reset(self):
        """Starts the nearest-point search from the path's beginning again."""
        self._hint = 0

    def nearest(self, position, hint=None):
        """(index, signed cross-track [m]) of the nearest sample searched around `hint` (default: last match)."""
        hint = self._hint if hint is None else hint
        lo = np.searchsorted(self.s, self.s[hint] - SEARCH_BACK_M)
        hi = np.searchsorted(self.s, self.s[hint] + SEARCH_AHEAD_M) + 1
        d = self.points[lo:hi] - np.asarray(position)[:2]
        i = lo + int(np.argmin(d[:, 0] ** 2 + d[:, 1] ** 2))
        psi = self.tangent[i]
        rel = np.asarray(position)[:2] - self.points[i]
        return i, float(-math.sin(psi) * rel[0] + math.cos(psi) * rel[1])

    def target(self, t, position, heading):
        """The target at the point of the path nearest to `position`: its tangent, curvature and the cross-
        track error."""
        i, e = self.nearest(position)
        self._hint = i
        return Target(self.speed, float(self.tangent[i]), float(self.curvature[i]), e)

    def curvature_ahead(self, distances):
        """The path's curvature at `distances` [m] from the last nearest point (held beyond the ends)."""
        return tuple(np.interp(self.s[self._hint] + np.asarray(distances, dtype=float), self.s, self.curvature))

    def cross_track(self, positions):
        """Signed cross-track error (n,) of a sequence of positions (n, ≥2), matched in order."""
        hint, out = 0, np.empty(len(positions))
        for k, p in enumerate(positions):
            hint, out[k] = self.nearest(p, hint)
        return out


def path_points(kind, length, radius=None, size=None, start=None, points=None, ds=PATH_DS):
    """How many samples the path of `kind` covering `length` m has (as the functions below build
    it; None for a speed or heading reference): what a task's memory estimate reads before
    anything is built."""
    if kind == "line":
        return (length + 1.0) / ds + 1
    if kind == "circle":
        laps = math.ceil(length / (2 * math.pi * radius)) + 1
        return 2 * math.pi * radius * laps / ds + 2
    if kind == "figure8":
        laps = math.ceil(length / (4 * math.pi * size)) + 1
        return 2 * laps * (2 * math.pi * size / ds + 2)
    if kind == "waypoints":
        corners = np.vstack([np.asarray(start, dtype=np.float64)[None, :2], np.asarray(points, dtype=np.float64)])
        legs = np.hypot(*np.diff(corners, axis=0).T)
        return float(np.sum(np.maximum(legs / ds, 1.0))) + 2.0 / ds + 1
    return None


def _arc(center, radius, start_angle, sweep, ds=PATH_DS):
    n = max(int(abs(sweep) * radius / ds), 2)
    a = start_angle + np.linspace(0.0, sweep, n + 1)
    return center + radius * np.stack([np.cos(a), np.sin(a)], axis=1)


def line_path(start, psi0, offset, length, speed):
    """A straight line in the direction ψ0 through the point `offset` m to the left of `start`."""
    n_left = np.array([-math.sin(psi0), math.cos(psi0)])
    t = np.array([math.cos(psi0), math.sin(psi0)])
    origin = np.asarray(start) + offset * n_left - 1.0 * t
    s = np.arange(0.0, length + 1.0, PATH_DS)
    return Path(origin + s[:, None] * t, speed)


def circle_path(start, psi0, radius, length, speed):
    """A circle of `radius` through `start`, tangent to ψ0 there, turning left; laps to cover `length`."""
    center = np.asarray(start) + radius * np.array([-math.sin(psi0), math.cos(psi0)])
    laps = math.ceil(length / (2 * math.pi * radius)) + 1
    return Path(_arc(center, radius, psi0 - math.pi / 2, 2 * math.pi * laps), speed)


def figure8_path(start, psi0, lobe_radius, length, speed):
    """Two circles of `lobe_radius` touching at `start`: the left lobe first (turning left), then the right one."""
    n_left = np.array([-math.sin(psi0), math.cos(psi0)])
    start = np.asarray(start)
    laps = math.ceil(length / (4 * math.pi * lobe_radius)) + 1
    pieces = []
    for _ in range(laps):
        left = _arc(start + lobe_radius * n_left, lobe_radius, psi0 - math.pi / 2, 2 * math.pi)
        right = _arc(start - lobe_radius * n_left, lobe_radius, psi0 + math.pi / 2, -2 * math.pi)
        pieces += [left[:-1] if pieces == [] else left[1:-1], right[1:]]
    return Path(np.concatenate(pieces), speed)


def waypoints_path(start, points, speed, ds=PATH_DS):
    """Straight legs from `start` through every point in order, then straight on past the last one."""
    corners = np.vstack([np.asarray(start)[None, :2], np.asarray(points, dtype=np.float64)])
    pieces = []
    for a, b in zip(corners[:-1], corners[1:]):
        n = max(int(np.hypot(*(b - a)) / ds), 1)
        pieces.append(a + np.linspace(0.0, 1.0, n + 1)[:-1, None] * (b - a))
    last = corners[-1] - corners[-2]
    tail = corners[-1] + np.arange(0.0, 2.0, ds)[:, None] * (last / np.hypot(*last))
    return Path(np.concatenate(pieces + [tail]), speed)
