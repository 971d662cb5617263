"""Trapezoidal speed profiles, the shape of every move the controller plans.

A move over a distance ``d`` (rad for the leading joint of a ``movej``, m of TCP path for a
``movel``) accelerates with ``a`` up to ``v``, cruises, and decelerates with ``a``::

    t_acc = v / a                  if d >= v²/a   (trapezoid)
    t_flat = (d - v²/a) / v
    T = 2·t_acc + t_flat

    t_acc = sqrt(d / a), t_flat = 0, peak speed sqrt(a·d)   otherwise (triangle)

With a time ``t`` given (``movej(q, t=2)``: time has priority over speed and acceleration),
the profile keeps the shape of the (a, v) profile and is stretched to last ``t`` when that is
longer; a ``t`` shorter than the fastest (a, v) profile is not reachable within ``a`` and
``v``, and the profile then uses the acceleration ``4·d/t²`` of a triangle lasting ``t`` —
the controller does not document this case [U], the verifier reports its speeds.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["Trapezoid", "positions", "speeds"]


@dataclass(slots=True)
class Trapezoid:
    """A trapezoidal (or triangular) profile over ``distance`` ≥ 0.

    ``accel`` in units/s², ``peak`` the cruise speed in units/s, ``t_acc`` and ``t_flat`` in s.
    """

    distance: float
    accel: float
    peak: float
    t_acc: float
    t_flat: float

    @classmethod
    def plan(cls, distance: float, v: float, a: float, t: float = 0.0) -> Trapezoid:
        """The profile for ``distance`` with speed ``v`` and acceleration ``a`` (> 0), or
        lasting ``t`` s when ``t`` > 0."""
        distance = abs(float(distance))
        if distance == 0.0:
            return cls(0.0, a, 0.0, 0.0, max(t, 0.0))
        if v <= 0 or a <= 0:
            raise ValueError("speed and acceleration must be positive")
        if distance >= v * v / a:
            t_acc = v / a
            profile = cls(distance, a, v, t_acc, (distance - v * v / a) / v)
        else:
            t_acc = math.sqrt(distance / a)
            profile = cls(distance, a, a * t_acc, t_acc, 0.0)
        if t > 0:
            return profile.stretched(t)
        return profile

    def stretched(self, total: float) -> Trapezoid:
        """The same shape lasting ``total`` s (slower); or a triangle lasting ``total`` when
        ``total`` is shorter than this profile."""
        if self.distance == 0.0:
            return Trapezoid(0.0, self.accel, 0.0, 0.0, total)
        if total >= self.duration:
            scale = self.duration / total
            return Trapezoid(self.distance, self.accel * scale * scale, self.peak * scale,
                             self.t_acc / scale, self.t_flat / scale)
        accel = 4.0 * self.distance / (total * total)
        return Trapezoid(self.distance, accel, accel * total / 2, total / 2, 0.0)

    @property
    def duration(self) -> float:
        """Total time in s."""
        return 2.0 * self.t_acc + self.t_flat

    def position(self, t: np.ndarray | float) -> np.ndarray:
        """Distance covered at times ``t`` (s from the start), clipped to [0, duration]."""
        t = np.asarray(t, dtype=float)
        return positions(t, self.distance, self.accel, self.peak, self.t_acc, self.t_flat)

    def speed(self, t: np.ndarray | float) -> np.ndarray:
        """Speed at times ``t`` (units/s)."""
        t = np.asarray(t, dtype=float)
        ta, tf = self.t_acc, self.t_flat
        if self.distance == 0.0:
            return np.zeros_like(t)
        inside = (t >= 0) & (t <= self.duration)
        up = self.accel * t
        down = self.accel * (self.duration - t)
        speed = np.where(t < ta, up, np.where(t < ta + tf, self.peak, down))
        return np.where(inside, speed, 0.0)

    def time_at(self, s: float) -> float:
        """The time (s) at which the distance ``s`` is reached."""
        s = min(max(s, 0.0), self.distance)
        a, ta = self.accel, self.t_acc
        d_acc = 0.5 * a * ta * ta
        if self.distance == 0.0:
            return 0.0
        if s <= d_acc:
            return math.sqrt(2.0 * s / a)
        if s <= self.distance - d_acc:
            return ta + (s - d_acc) / self.peak
        rest = self.distance - s
        return self.duration - math.sqrt(2.0 * rest / a)


def positions(t, distance, accel, peak, t_acc, t_flat) -> np.ndarray:
    """Distance covered at times ``t`` (s since each profile's start) for many profiles at
    once: every argument is a scalar or an array broadcasting with ``t``; times are clipped
    to [0, duration]. A profile of zero distance stays at 0."""
    duration = 2.0 * t_acc + t_flat
    t = np.clip(t, 0.0, duration)
    # each branch is computed everywhere and picked by np.where: with absurd parameters
    # (a=1e300) the branches not taken may overflow, which is no error of the one taken
    with np.errstate(over="ignore", invalid="ignore"):
        rising = 0.5 * accel * t * t
        cruising = 0.5 * accel * t_acc * t_acc + peak * (t - t_acc)
        rest = duration - t
        falling = distance - 0.5 * accel * rest * rest
    result = np.where(t < t_acc, rising, np.where(t < t_acc + t_flat, cruising, falling))
    return np.where(distance == 0.0, 0.0, result)


def speeds(t, distance, accel, peak, t_acc, t_flat) -> np.ndarray:
    """Speed (units/s) at times ``t`` for many profiles at once, like :func:`positions`;
    0 outside [0, duration]."""
    duration = 2.0 * t_acc + t_flat
    inside = (t >= 0.0) & (t <= duration)
    speed = np.where(t < t_acc, accel * t,
                     np.where(t < t_acc + t_flat, peak, accel * (duration - t)))
    return np.where(inside & (distance > 0.0), speed, 0.0)
