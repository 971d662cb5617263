"""Which UR arm was a program taught on? Fit taught (joints, pose) pairs against every model.

PolyScope stores each taught waypoint twice: the joint positions and the TCP pose the
controller computed from them. Only the arm the program was taught on maps the joints to the
poses: for that model the forward kinematics, followed by the active TCP, reproduces every
pose to about a millimetre (the controller uses the arm's factory calibration, the nominal DH
table differs from it by that much); any other model misses by centimetres.

:func:`fit_models` evaluates every model at once with the closed-form batched FK of
:func:`urdsl.kinematics.dh.fk_ur` (models with the same DH table, e.g. UR5e and UR7e, are one
arm and evaluated once). :func:`identify` decides: the model whose residual is within
``tolerance`` for most pairs, unless another arm fits about as well.

The TCP is either given (the ``set_tcp`` in force when the waypoints were taught) or, when
that does not fit and there are at least three pairs, solved for as one constant offset
``X`` with ``pose_i = flange_i · X``: with ``t_i = R_flange_iᵀ (p_i − f_i)`` the least-squares
translation is the mean of the ``t_i`` (the residual ``p_i − (f_i + R_i t)`` has the norm of
``t_i − t``), and the rotation is the projection onto SO(3) of ``Σ R_flange_iᵀ R_pose_i``.

Lengths in m, angles in rad.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from . import pose as pose_math
from .dh import fk_ur
from .models import MODELS, ModelSpec

__all__ = ["ModelFit", "Identification", "fit_models", "identify", "same_arm_groups",
           "TOLERANCE"]

TOLERANCE = 0.008
"""Position residual [m] under which a pair counts as explained by a model. Nominal DH
against a calibrated arm differs by about 1 mm on small arms and up to 7 mm on a UR20
(measured over 2,600 waypoints of one real UR20 project: 99 % under 6 mm); two different
arms with the same joints differ by more than 8 mm at 99 % of random joint positions (the
closest pairs: UR20/UR30 and UR15/UR18)."""

MIN_SHARE = 0.6
"""Share of the pairs a model must explain to be taken (waypoints taught with another TCP, or
edited by hand, may not fit)."""

MIN_EXACT = 3
"""With fewer than :data:`MIN_SHARE` of the pairs explained, a model is still taken when it
explains at least this many and no other arm a third as many."""


@dataclass(frozen=True)
class ModelFit:
    """How well one arm maps the joints to the poses.

    ``model``: the representative name (first in :data:`MODELS` order); ``same_arm``: other
    model names with the same DH table; ``errors``: position error of each pair [m];
    ``rotation_errors``: orientation error of each pair [rad]; ``tcp``: the TCP pose used
    (given or fitted) as (x, y, z, rx, ry, rz); ``tcp_fitted``: whether it was solved for.
    """

    model: str
    same_arm: tuple[str, ...]
    errors: np.ndarray
    rotation_errors: np.ndarray
    tcp: tuple[float, ...]
    tcp_fitted: bool = False

    def inliers(self, tolerance: float = TOLERANCE) -> np.ndarray:
        """Mask of the pairs this model explains within ``tolerance`` [m]."""
        return self.errors <= tolerance

    def rms(self, mask: np.ndarray | None = None) -> float:
        """Root-mean-square position error [m] over the pairs in ``mask`` (default all)."""
        errors = self.errors if mask is None else self.errors[mask]
        return float(np.sqrt(np.mean(errors ** 2))) if errors.size else math.inf


@dataclass(frozen=True)
class Identification:
    """The outcome of :func:`identify`.

    ``model`` is ``None`` when no arm explains the pairs (``reason`` says why). ``residual``:
    RMS position error [m] over the explained pairs; ``used``: how many pairs the model
    explains of ``pairs``; ``same_arm``: model names with the identical arm (the choice among
    them is arbitrary: kinematics cannot tell them apart); ``runner_up``: the best other arm
    and its RMS residual [m]; ``fits``: every arm, best first.
    """

    model: str | None
    pairs: int
    used: int = 0
    residual: float = math.inf
    rotation_residual: float = math.inf
    same_arm: tuple[str, ...] = ()
    tcp: tuple[float, ...] | None = None
    tcp_fitted: bool = False
    runner_up: tuple[str, float] | None = None
    reason: str = ""
    fits: tuple[ModelFit, ...] = field(default=(), repr=False)


def same_arm_groups(models: dict[str, ModelSpec] | None = None) -> list[tuple[str, ...]]:
    """Model names grouped by identical DH tables, in :data:`MODELS` order."""
    groups: dict[tuple, list[str]] = {}
    for name, spec in (models or MODELS).items():
        key = tuple(np.round(np.concatenate([spec.dh_a, spec.dh_d]), 9))
        groups.setdefault(key, []).append(name)
    return [tuple(names) for names in groups.values()]


def _as_arrays(joints, poses) -> tuple[np.ndarray, np.ndarray]:
    q = np.asarray(joints, dtype=float).reshape(-1, 6)
    p = np.asarray(poses, dtype=float).reshape(-1, 6)
    if q.shape[0] != p.shape[0]:
        raise ValueError(f"{q.shape[0]} joint vectors but {p.shape[0]} poses")
    return q, p


def _project_rotation(m: np.ndarray) -> np.ndarray:
    """The rotation matrix nearest to ``m`` (3x3) in the Frobenius norm."""
    u, _, vt = np.linalg.svd(m)
    d = np.sign(np.linalg.det(u @ vt)) or 1.0
    return u @ np.diag([1.0, 1.0, d]) @ vt


def _candidates(tcp) -> np.ndarray:
    """TCP candidates (K, 4, 4) from one pose (6,), several (K, 6) or ``None`` (the flange)."""
    values = np.asarray(tcp if tcp is not None else [0.0] * 6, float).reshape(-1, 6)
    return pose_math.to_matrix(values)


def fit_models(joints, poses, tcp=None, *, fit_tcp: bool = False,
               models: dict[str, ModelSpec] | None = None) -> list[ModelFit]:
    """Every arm's fit of ``poses`` (N, 6: TCP poses in Base, m and rotation vector) from
    ``joints`` (N, 6, rad), best (lowest RMS) first.

    ``tcp``: the TCP pose in the flange frame (default: the flange), or several candidates
    (K, 6): a program with several TCPs teaches each waypoint with one of them, so each pair
    is fitted with the candidate that explains it best (the fit's ``tcp`` is the one used
    most). With ``fit_tcp`` the TCP is instead solved for per arm as one constant offset
    (needs at least 2 pairs to mean anything, 3 to tell arms apart).
    """
    q, p = _as_arrays(joints, poses)
    target = pose_math.to_matrix(p)
    known = _candidates(tcp)
    fits = []
    models = models or MODELS
    for group in same_arm_groups(models):
        spec = models[group[0]]
        flange = fk_ur(q, spec.d1, spec.a2, spec.a3, spec.d4, spec.d5, spec.d6)
        if fit_tcp and len(q):
            rt = np.swapaxes(flange[:, :3, :3], 1, 2)
            local = np.einsum("nij,nj->ni", rt, target[:, :3, 3] - flange[:, :3, 3])
            offset = np.eye(4)
            offset[:3, 3] = local.mean(axis=0)
            offset[:3, :3] = _project_rotation(np.einsum("nij,njk->ik", rt,
                                                         target[:, :3, :3]))
        else:
            offset = known[0]
        offsets = offset[None] if fit_tcp else known
        predicted = flange[None] @ offsets[:, None]                          # (K, N, 4, 4)
        errors = np.linalg.norm(predicted[..., :3, 3] - target[None, :, :3, 3], axis=-1)
        best = np.argmin(errors, axis=0) if len(q) else np.zeros(0, int)
        pick = predicted[best, np.arange(len(q))]
        rotation = np.atleast_1d(pose_math.rotation_angle(pick[:, :3, :3], target[:, :3, :3]))
        if not fit_tcp and len(q):
            offset = offsets[np.bincount(best, minlength=len(offsets)).argmax()]
        fits.append(ModelFit(group[0], group[1:], errors[best, np.arange(len(q))],
                             np.asarray(rotation, float),
                             tuple(float(v) for v in pose_math.from_matrix(offset)), fit_tcp))
    fits.sort(key=lambda fit: fit.rms())
    return fits


def _decide(fits: list[ModelFit], pairs: int, tolerance: float,
            min_share: float) -> Identification | None:
    """The identification from one set of fits, or ``None`` when no arm explains enough."""
    def score(fit: ModelFit):
        mask = fit.inliers(tolerance)
        return (-int(mask.sum()), fit.rms(mask))

    ranked = sorted(fits, key=score)
    best = ranked[0]
    mask = best.inliers(tolerance)
    used = int(mask.sum())
    runner = ranked[1] if len(ranked) > 1 else None
    runner_used = int(runner.inliers(tolerance).sum()) if runner is not None else 0
    # most pairs explained; or, when some waypoints were taught with a TCP the program no
    # longer names, enough exact fits that no other arm comes near
    if used == 0 or (used < min_share * pairs
                     and (used < MIN_EXACT or runner_used * 3 > used)):
        return None
    runner_up = (runner.model, runner.rms()) if runner is not None else None
    if runner is not None:
        if runner_used >= used and runner.rms(runner.inliers(tolerance)) <= 2 * best.rms(mask):
            return Identification(
                None, pairs, reason=f"the waypoints fit {best.model} and {runner.model} "
                f"about equally ({best.rms(mask) * 1000:.1f} and "
                f"{runner.rms(runner.inliers(tolerance)) * 1000:.1f} mm)",
                runner_up=runner_up, fits=tuple(fits))
    return Identification(
        best.model, pairs, used, best.rms(mask),
        float(np.sqrt(np.mean(best.rotation_errors[mask] ** 2))), best.same_arm, best.tcp,
        best.tcp_fitted, runner_up, fits=tuple(fits))


def identify(joints, poses, tcp=None, *, tolerance: float = TOLERANCE,
             min_share: float = MIN_SHARE,
             models: dict[str, ModelSpec] | None = None) -> Identification:
    """The arm that maps ``joints`` (N, 6, rad) to ``poses`` (N, 6, TCP poses in Base).

    First with the given ``tcp`` (flange frame, one pose or several candidates, see
    :func:`fit_models`; default the flange); if no arm explains at
    least ``min_share`` of the pairs within ``tolerance`` [m] and there are three pairs or more,
    again with a TCP solved for per arm. Two different arms explaining the pairs about
    equally well (possible with few, similar pairs) give no answer.
    """
    q, p = _as_arrays(joints, poses)
    pairs = len(q)
    if pairs == 0:
        return Identification(None, 0, reason="no taught waypoint pairs")
    fits = fit_models(q, p, tcp, models=models)
    found = _decide(fits, pairs, tolerance, min_share)
    if (found is None or found.model is None) and pairs >= 3:
        free = fit_models(q, p, fit_tcp=True, models=models)
        refit = _decide(free, pairs, tolerance, min_share)
        if refit is not None and (refit.model is not None or found is None):
            found = refit
    if found is not None:
        return found
    best = fits[0]
    most = max(fits, key=lambda fit: int(fit.inliers(tolerance).sum()))
    fitting = int(most.inliers(tolerance).sum())
    arms = sorted(((int(f.inliers(tolerance).sum()), f.model) for f in fits
                   if f.inliers(tolerance).any()), reverse=True)
    if len(arms) > 1:
        reason = "the pairs fit different arms (" + ", ".join(
            f"{count} {model}" for count, model in arms) + ")"
    elif fitting:
        reason = (f"only {fitting} of {pairs} pair(s) fit {most.model} within "
                  f"{tolerance * 1000:g} mm (the others were taught with a TCP or frame "
                  "the program does not show?)")
    else:
        reason = (f"no UR model maps the joints to the poses (best {best.model}: "
                  f"{best.rms() * 1000:.0f} mm RMS over {pairs} pair(s))")
    return Identification(None, pairs, residual=best.rms(),
                          runner_up=(best.model, best.rms()), reason=reason, fits=tuple(fits))
