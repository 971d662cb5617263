"""A UR arm: forward and inverse kinematics, joint limits and singularity measures.

Frames: everything is in the controller's Base frame (ROS ``base``; ROS ``base_link`` is
turned by π about z from it). With ``tcp=None`` the tool point is the flange (DH frame 6,
ROS ``tool0``, Z out of the flange); a TCP is a pose ``p[x, y, z, rx, ry, rz]`` of the tool
point in the flange frame (as ``set_tcp`` takes it) or a 4x4 matrix.

Which solution the controller takes
-----------------------------------
``get_inverse_kin``/``movej`` to a pose pick, among the (up to eight) analytic solutions, the
one closest to ``q_near`` in the sum of squared joint differences. Each joint may first be
moved by a multiple of 2π to the value nearest ``q_near`` within the joint limits
(±2π: the arm can reach every angle in two ways), so a solution at −3.1 rad becomes +3.18
when ``q_near`` is 3.0.

Calibration
-----------
With a :class:`~urdsl.kinematics.calibration.Calibration`, FK uses the corrected DH table. IK
solves the nominal arm analytically, then refines each solution by Newton steps on the
corrected chain (Pinocchio for single poses, the same iteration in NumPy for batches), so that
``fk(ik(x)) == x`` holds for the calibrated robot.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from . import ik as _ik
from . import pose as _pose
from .calibration import Calibration
from .dh import arm_terms, dh_frames, fk_ur, ur_axes
from .errors import KinematicsError
from .models import ModelSpec, model_spec
from .pinmodel import URDF_MODELS, build_dh_model, load_urdf_model

__all__ = ["Robot"]

#: A calibrated pose counts as solved when the refined FK error is below this [m, rad].
REFINE_TOLERANCE = 1e-12
#: Nominal branches out of reach by less than this [m] are still refined for a calibrated arm.
CALIBRATED_REACH_SLACK = 0.01
#: Elbow angle [rad] from which a calibrated arm's solution is refined when the nominal one
#: lies closer to the stretched elbow (θ3 = 0): see :func:`_elbow_seeds`.
ELBOW_SEED = 0.02


def _elbow_seeds(guesses: np.ndarray, side: np.ndarray) -> np.ndarray:
    """Nominal solutions ``guesses`` (..., 6) as starting points for a calibrated arm's
    Newton steps, each on its elbow side ``side`` (+1: θ3 ≥ 0, −1: θ3 ≤ 0; one per guess,
    shape ``guesses.shape[:-1]`` or broadcast to it).

    Near the stretched elbow the two elbow solutions of a pose lie a few hundredths of a
    radian either side of θ3 = 0 on the calibrated arm, and the nominal ones may coincide at
    0 (a pose the calibrated arm reaches lies just beyond the nominal reach, where both are
    clamped to the boundary): refined from there, both converge to the same solution and
    the arm's own solution is missed — the taught joints of a pose taught stretched out. A
    guess within :data:`ELBOW_SEED` of 0 therefore starts at ±ELBOW_SEED on its side."""
    seeds = np.array(guesses, dtype=float)
    theta3 = seeds[..., 2]
    seeds[..., 2] = np.where(np.abs(theta3) < ELBOW_SEED, side * ELBOW_SEED, theta3)
    return seeds


#: A calibrated arm's solution more than this [rad] (largest joint) from ``q_near`` is solved
#: again from ``q_near`` itself (:meth:`Robot.ik_many`): a joint moves at most 0.1 rad
#: between two trace samples, a branch change about π.
RESEED_STEP = 0.1

#: The elbow side of each analytic branch (k % 2 = 0: θ3 = +acos(…), 1: −acos(…)).
_BRANCH_SIDE = np.where(np.arange(8) % 2 == 0, 1.0, -1.0)


def _readonly(array: np.ndarray) -> np.ndarray:
    array = np.array(array, dtype=float)
    array.setflags(write=False)
    return array


def _joints(q, name: str = "q") -> np.ndarray:
    array = np.asarray(q, dtype=float)
    if array.shape != (6,):
        raise KinematicsError(f"{name} must be 6 joint angles [rad], got shape {array.shape}")
    if not np.all(np.isfinite(array)):
        raise KinematicsError(f"{name} must be finite, got {array.tolist()}")
    return array


def _joint_batch(q, name: str = "Q") -> np.ndarray:
    array = np.asarray(q, dtype=float)
    if array.ndim == 1 and array.shape == (6,):
        array = array[None]
    if array.ndim != 2 or array.shape[1] != 6:
        raise KinematicsError(f"{name} must have shape (N, 6), got {array.shape}")
    return array


def _transform(x, name: str = "pose") -> np.ndarray:
    """A 4x4 matrix from a pose (6,) or a matrix (4, 4)."""
    array = np.asarray(x, dtype=float)
    if array.shape == (6,):
        return _pose.to_matrix(array)
    if array.shape == (4, 4):
        return array
    raise KinematicsError(f"{name} must be a pose (6 numbers) or a 4x4 matrix, got shape "
                          f"{array.shape}")


def _transform_batch(x, name: str = "poses") -> np.ndarray:
    array = np.asarray(x, dtype=float)
    if array.ndim == 2 and array.shape[1] == 6:
        return _pose.to_matrix(array)
    if array.ndim == 3 and array.shape[1:] == (4, 4):
        return array
    if array.shape in ((6,), (4, 4)):
        return _transform(array, name)[None]
    raise KinematicsError(f"{name} must have shape (N, 6) or (N, 4, 4), got {array.shape}")


_TCP_CACHE: dict[bytes, np.ndarray | None] = {}
"""TCP poses (6,) already converted to matrices, by the bytes of the pose: a program sets a
few TCPs and every forward-kinematics call of the checker converts one of them."""


def _tcp(tcp) -> np.ndarray | None:
    """The TCP (a pose (6,) or a matrix (4, 4)) as a read-only matrix; None for the flange."""
    if tcp is None:
        return None
    if isinstance(tcp, np.ndarray) and tcp.shape == (6,) and tcp.dtype == float:
        key = tcp.tobytes()
        if key not in _TCP_CACHE:
            if len(_TCP_CACHE) > 1024:
                _TCP_CACHE.clear()
            _TCP_CACHE[key] = _tcp_matrix(tcp)
        return _TCP_CACHE[key]
    return _tcp_matrix(tcp)


def _tcp_matrix(tcp) -> np.ndarray | None:
    matrix = _transform(tcp, "tcp")
    if np.array_equal(matrix, np.eye(4)):
        return None
    matrix = np.array(matrix, dtype=float)
    matrix.setflags(write=False)
    return matrix


def _inverse(matrix: np.ndarray) -> np.ndarray:
    out = np.eye(4)
    out[:3, :3] = matrix[:3, :3].T
    out[:3, 3] = -matrix[:3, :3].T @ matrix[:3, 3]
    return out


def _dedupe(solutions: np.ndarray, tolerance: float = 1e-9) -> np.ndarray:
    """Drop solutions equal (mod 2π, within ``tolerance`` rad) to an earlier one."""
    if len(solutions) < 2:
        return solutions.reshape(-1, 6)
    difference = solutions[:, None, :] - solutions[None, :, :]
    difference -= 2.0 * np.pi * np.rint(difference / (2.0 * np.pi))
    same = np.max(np.abs(difference), axis=2) < tolerance
    keep = ~np.any(np.triu(same, 1), axis=0)
    return solutions[keep]


class Robot:
    """One UR arm (see the module docstring for frames and conventions).

    Build it with :meth:`Robot.model`. ``spec`` is its :class:`ModelSpec`; ``q_min``,
    ``q_max`` [rad] and ``qd_max`` [rad/s] are read-only (6,) arrays; ``pin_model`` /
    ``pin_data`` the Pinocchio model built from the (calibrated) DH table.
    """

    def __init__(self, spec: ModelSpec, calibration: Calibration | None = None) -> None:
        self.spec = spec
        if calibration is not None and calibration.is_zero and calibration.model in (None,
                                                                                    spec.name):
            calibration = None
        self.calibration = calibration
        if calibration is None:
            theta, a, d, alpha = np.zeros(6), spec.dh_a, spec.dh_d, spec.dh_alpha
        else:
            theta, a, d, alpha = calibration.dh(spec)
        self._dh = tuple(_readonly(v) for v in (theta, a, d, alpha))
        self._nominal = (spec.d1, spec.a2, spec.a3, spec.d4, spec.d5, spec.d6)
        self.pin_model = build_dh_model(spec.name, *self._dh, spec.q_min, spec.q_max,
                                        spec.qd_max)
        self.pin_data = self.pin_model.createData()
        self._flange = self.pin_model.getFrameId("tool0")

    @classmethod
    def model(cls, name: str, calibration: Calibration | None = None) -> Robot:
        """The robot of model ``name`` (``"ur5e"``, ``"UR10"``, …), optionally calibrated.

        Raises :class:`KinematicsError` for an unknown name, listing the known ones.
        """
        return cls(model_spec(name), calibration)

    # -- data -----------------------------------------------------------------------------

    @property
    def name(self) -> str:
        return self.spec.name

    @property
    def q_min(self) -> np.ndarray:
        """Lower joint position limits [rad] (−∞ for an unlimited joint)."""
        return self.spec.q_min

    @property
    def q_max(self) -> np.ndarray:
        """Upper joint position limits [rad] (+∞ for an unlimited joint)."""
        return self.spec.q_max

    @property
    def qd_max(self) -> np.ndarray:
        """Joint speed limits [rad/s]."""
        return self.spec.qd_max

    @property
    def dh(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The DH table in use ``(theta_offset, a, d, alpha)`` (rad, m, m, rad)."""
        return self._dh

    @property
    def calibrated(self) -> bool:
        return self.calibration is not None

    def __repr__(self) -> str:
        return f"Robot({self.name!r}{', calibrated' if self.calibrated else ''})"

    def within_limits(self, Q) -> np.ndarray:
        """(N,) True where every joint of ``Q`` (N, 6) lies within the position limits."""
        Q = _joint_batch(Q)
        return np.all((Q >= self.q_min) & (Q <= self.q_max), axis=1)

    def urdf_model(self) -> pin.Model:
        """The example-robot-data URDF model (UR3, UR5, UR10 only; root ``base_link``, frames
        ``base`` = controller Base and ``tool0`` = flange). Raises :class:`KinematicsError`
        for the other models."""
        if self.name not in URDF_MODELS:
            raise KinematicsError(f"there is no URDF model of the {self.name}; example-robot-"
                                  "data describes " + ", ".join(URDF_MODELS))
        return load_urdf_model(self.name)

    # -- forward kinematics ---------------------------------------------------------------

    def fk(self, q, tcp=None) -> np.ndarray:
        """The TCP pose (4, 4) in Base for joints ``q`` (6,) [rad] (Pinocchio)."""
        q = _joints(q)
        pin.forwardKinematics(self.pin_model, self.pin_data, q)
        flange = pin.updateFramePlacement(self.pin_model, self.pin_data, self._flange)
        matrix = flange.homogeneous
        tcp = _tcp(tcp)
        return matrix if tcp is None else matrix @ tcp

    def fk_pose(self, q, tcp=None) -> np.ndarray:
        """The TCP pose as ``p[x, y, z, rx, ry, rz]`` (6,) for joints ``q`` (6,)."""
        return _pose.from_matrix(self.fk(q, tcp))

    def fk_many(self, Q, tcp=None) -> np.ndarray:
        """TCP poses (N, 4, 4) for joint vectors ``Q`` (N, 6), vectorised in NumPy (closed
        form for a nominal arm, the DH product for a calibrated one)."""
        Q = _joint_batch(Q)
        if self.calibration is None:
            out = fk_ur(Q, *self._nominal)
        else:
            out = dh_frames(Q, *self._dh)[:, 6]
        tcp = _tcp(tcp)
        return out if tcp is None else out @ tcp

    def frames_many(self, Q) -> np.ndarray:
        """DH frames 0…6 (N, 7, 4, 4) in Base for joint vectors ``Q`` (N, 6)."""
        return dh_frames(_joint_batch(Q), *self._dh)

    def axes_many(self, Q) -> tuple[np.ndarray, np.ndarray]:
        """Joint axes (N, 6, 3) and origins of DH frames 0…6 (N, 7, 3) [m] in Base for joint
        vectors ``Q`` (N, 6): closed form for a nominal arm, the DH product for a calibrated
        one."""
        Q = _joint_batch(Q)
        if self.calibration is None:
            return ur_axes(Q, *self._nominal)
        frames = dh_frames(Q, *self._dh)
        return frames[:, :6, :3, 2], frames[:, :, :3, 3]

    def jacobian_many(self, Q, tcp=None) -> np.ndarray:
        """Geometric Jacobians (N, 6, 6) of the TCP at joint vectors ``Q`` (N, 6): rows
        (v [m/s], ω [rad/s]) in Base axes at the TCP point, columns per joint speed [rad/s].
        Column i is ``(z_i × (p − o_i), z_i)``."""
        axes, origins = self.axes_many(Q)
        tcp = _tcp(tcp)
        point = origins[:, 6]
        if tcp is not None and np.any(tcp[:3, 3] != 0.0):
            point = self.fk_many(Q, tcp)[:, :3, 3]
        linear = np.cross(axes, point[:, None] - origins[:, :6])
        return np.concatenate([linear, axes], axis=2).transpose(0, 2, 1)

    def jacobian(self, q) -> np.ndarray:
        """The geometric Jacobian (6, 6) of the flange at ``q``: rows (v [m/s], ω [rad/s]) in
        Base axes at the flange origin, columns per joint speed [rad/s] (Pinocchio)."""
        q = _joints(q)
        return pin.computeFrameJacobian(self.pin_model, self.pin_data, q, self._flange,
                                        pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)

    # -- inverse kinematics ---------------------------------------------------------------

    def _flange_targets(self, T: np.ndarray, tcp) -> np.ndarray:
        tcp = _tcp(tcp)
        return T if tcp is None else T @ _inverse(tcp)

    def _solve(self, flange: np.ndarray, q6_hint: np.ndarray | None
               ) -> tuple[np.ndarray, np.ndarray]:
        """Solutions (N, 8, 6) and misses (N, 8) [m] for flange poses (N, 4, 4)."""
        if self.calibration is None:
            return _ik.solve_ur(flange, *self._nominal, q6_hint=q6_hint)
        solutions, miss = _ik.solve_ur(flange, *self._nominal, q6_hint=q6_hint,
                                       reach_tolerance=CALIBRATED_REACH_SLACK)
        valid = ~np.isnan(solutions[..., 0])
        seeds = _elbow_seeds(solutions, _BRANCH_SIDE)
        refined, error = _ik.refine(seeds[valid], flange[np.nonzero(valid)[0]], *self._dh)
        good = error < REFINE_TOLERANCE
        out = np.full_like(solutions, np.nan)
        index_n, index_k = np.nonzero(valid)
        out[index_n[good], index_k[good]] = _ik.wrap(refined[good])
        # a branch that refined is solved; one that did not keeps the nominal miss (at least
        # a nanometre, so that it counts as missed)
        miss = np.where(np.isnan(out[..., 0]), np.maximum(miss, 1e-9), 0.0)
        return out, miss

    def _refine_pin(self, q: np.ndarray, target: np.ndarray) -> tuple[np.ndarray, float]:
        """Newton steps with Pinocchio's frame Jacobian (LOCAL) and SE3 log error."""
        goal = pin.SE3(target)
        model, data = self.pin_model, self.pin_data
        error = np.inf
        for _ in range(20):
            pin.forwardKinematics(model, data, q)
            current = pin.updateFramePlacement(model, data, self._flange)
            twist = pin.log6(current.actInv(goal)).vector
            error = float(np.linalg.norm(twist))
            if error < 1e-14:
                break
            jacobian = pin.computeFrameJacobian(model, data, q, self._flange,
                                                pin.ReferenceFrame.LOCAL)
            q = q + np.linalg.lstsq(jacobian, twist, rcond=None)[0]
        return q, error

    def _refine_from(self, q: np.ndarray, flange: np.ndarray) -> np.ndarray:
        """A calibrated arm's solutions (M, 6) for flange poses (M, 4, 4) found by Newton
        steps from the joints ``q`` (M, 6) themselves; NaN rows where they do not converge."""
        refined, error = _ik.refine(q, flange, *self._dh)
        refined[~(error < REFINE_TOLERANCE)] = np.nan
        return refined

    def ik_all(self, T, tcp=None, q6_hint: float = 0.0) -> np.ndarray:
        """All inverse kinematics solutions (k, 6), k ≤ 8, joints wrapped to (−π, π].

        ``T`` is the TCP pose (4x4 or pose 6-vector) in Base. ``q6_hint`` [rad] is used for
        wrist 3 at the wrist singularity (θ5 = 0, where only θ4 + θ6 is determined). Returns an
        empty (0, 6) array when the pose is out of reach (see :meth:`out_of_reach`).
        """
        flange = self._flange_targets(_transform(T)[None], tcp)
        hint = np.array([q6_hint], dtype=float)
        if self.calibration is None:
            solutions, _ = _ik.solve_ur(flange, *self._nominal, q6_hint=hint)
            candidates = solutions[0][~np.isnan(solutions[0, :, 0])]
            return _dedupe(candidates)
        solutions, _ = _ik.solve_ur(flange, *self._nominal, q6_hint=hint,
                                    reach_tolerance=CALIBRATED_REACH_SLACK)
        present = ~np.isnan(solutions[0, :, 0])
        guesses = _elbow_seeds(solutions[0][present], _BRANCH_SIDE[present])
        # the batched solvers' damped Newton steps; where they do not converge (near a
        # singularity of the nominal guess), Pinocchio's least-squares steps
        refined, errors = _ik.refine(guesses, np.repeat(flange, len(guesses), axis=0),
                                     *self._dh)
        found = [q for q, error in zip(refined, errors, strict=True)
                 if error < REFINE_TOLERANCE]
        for guess in guesses[errors >= REFINE_TOLERANCE]:
            q, error = self._refine_pin(guess, flange[0])
            if error < REFINE_TOLERANCE:
                found.append(q)
        return _dedupe(_ik.wrap(np.array(found).reshape(-1, 6)))

    def out_of_reach(self, T, tcp=None) -> np.ndarray:
        """How far (m) each pose (N, 4, 4) or (N, 6) lies outside the reach, 0 when some
        analytic branch solves it (see :mod:`urdsl.kinematics.ik` for the measure)."""
        flange = self._flange_targets(_transform_batch(T), tcp)
        _, miss = self._solve(flange, None)
        return np.min(miss, axis=1)

    def ik(self, T, q_near, tcp=None) -> np.ndarray:
        """The controller's solution (6,) for TCP pose ``T``: the one closest to ``q_near``,
        each joint possibly moved by ±2π within the limits (see the module docstring).

        Raises :class:`KinematicsError` when the pose is out of reach (``distance`` = metres
        out of reach) or no solution fits the joint limits (``distance`` = 0).
        """
        q_near = _joints(q_near, "q_near")
        T = _transform(T)
        solutions = self.ik_all(T, tcp, q6_hint=float(q_near[5]))
        if self.calibration is not None:
            nearby = self._refine_from(q_near[None], self._flange_targets(T[None], tcp))
            if not np.isnan(nearby[0, 0]):
                solutions = _dedupe(np.concatenate([solutions.reshape(-1, 6), nearby]))
        if len(solutions) == 0:
            distance = float(self.out_of_reach(T[None], tcp)[0])
            position = np.round(T[:3, 3], 4).tolist()
            raise KinematicsError(
                f"pose at {position} m is out of reach of the {self.name} by "
                f"{distance * 1000:.1f} mm", distance=distance,
                position=tuple(float(v) for v in T[:3, 3]))
        chosen, found = _ik.choose_nearest(solutions[None], q_near[None], self.q_min,
                                           self.q_max)
        if not found[0]:
            raise KinematicsError(f"no solution for this pose lies within the joint limits of "
                                  f"the {self.name}", distance=0.0)
        return chosen[0]

    def ik_many(self, T, q_near, tcp=None) -> np.ndarray:
        """The controller's solutions (N, 6) for TCP poses ``T`` (N, 4, 4) or (N, 6); NaN rows
        where a pose is out of reach or no solution fits the limits. ``q_near`` is (6,) for
        all rows or (N, 6), one per row."""
        flange = self._flange_targets(_transform_batch(T), tcp)
        n = flange.shape[0]
        near = np.asarray(q_near, dtype=float)
        if near.shape == (6,):
            near = np.broadcast_to(near, (n, 6))
        elif near.shape != (n, 6):
            raise KinematicsError(f"q_near must have shape (6,) or ({n}, 6), got {near.shape}")
        near = np.ascontiguousarray(near)
        if self.calibration is None:
            solutions, _ = self._solve(flange, near[:, 5])
            chosen, _ = _ik.choose_nearest(solutions, near, self.q_min, self.q_max)
            return chosen
        # calibrated: refine only the nominal solution closest to q_near (the corrections
        # move a solution by well under a degree); rows where that fails get every branch
        solutions, _ = _ik.solve_ur(flange, *self._nominal, q6_hint=near[:, 5],
                                    reach_tolerance=CALIBRATED_REACH_SLACK)
        guess, found = _ik.choose_nearest(solutions, near, self.q_min, self.q_max)
        chosen = np.full((n, 6), np.nan)
        rows = np.flatnonzero(found)
        side = np.where(near[rows, 2] < 0.0, -1.0, 1.0)  # the side q_near is on
        refined, error = _ik.refine(_elbow_seeds(guess[rows], side), flange[rows], *self._dh)
        good = error < REFINE_TOLERANCE
        chosen[rows[good]], _ = _ik.choose_nearest(refined[good][:, None, :],
                                                   near[rows[good]], self.q_min, self.q_max)
        # near a singularity the nominal guess may refine to another of the calibrated
        # arm's solutions (a general 6R chain has up to 16); the one nearest q_near is then
        # found from q_near itself, as the arm continues from where it is
        far = np.flatnonzero(~(np.abs(chosen - near).max(axis=1) <= RESEED_STEP))
        if len(far):
            nearby = self._refine_from(near[far], flange[far])
            candidates = np.stack([chosen[far], nearby], axis=1)
            chosen[far], _ = _ik.choose_nearest(candidates, near[far], self.q_min,
                                                self.q_max)
        retry = np.flatnonzero(np.isnan(chosen[:, 0]))
        if len(retry):
            every, _ = self._solve(flange[retry], near[retry, 5])
            chosen[retry], _ = _ik.choose_nearest(every, near[retry], self.q_min, self.q_max)
        return chosen

    def ik_all_many(self, T, tcp=None) -> tuple[np.ndarray, np.ndarray]:
        """All solutions of many poses: (N, 8, 6) with NaN rows for missing branches (see
        :mod:`urdsl.kinematics.ik` for the branch order) and (N, 8) misses [m]."""
        flange = self._flange_targets(_transform_batch(T), tcp)
        return self._solve(flange, None)

    # -- singularities --------------------------------------------------------------------

    def singularity(self, Q) -> dict[str, np.ndarray]:
        """Distances to the three singularities and the manipulability, each (N,):

        * ``"shoulder"`` [m]: horizontal distance of the wrist centre (DH frame 5 origin)
          from the vertical plane through the base axis parallel to the shoulder axis,
          ``sqrt(r² − d4²)`` with ``r`` its distance to the base axis. 0: the base joint can
          no longer move the wrist centre sideways (the two shoulder solutions merge).
        * ``"elbow"`` [m]: how much the shoulder-to-wrist-1 distance ``L`` may still grow or
          shrink before the arm is fully stretched or folded,
          ``min(|a2| + |a3| − L, L − ||a2| − |a3||)``. 0: elbow singularity (θ3 = 0 or π).
        * ``"wrist"`` [rad]: angle between the wrist-1 and wrist-3 axes, folded into
          [0, π/2] (``|θ5|`` away from 0 or π on a nominal arm). 0: those axes are parallel.
        * ``"manipulability"`` [m³]: ``sqrt(det(J·Jᵀ)) = |det J|`` of the 6x6 flange
          Jacobian (rows m/s and rad/s); 0 at every singularity.

        On a nominal arm all four are closed forms of the joints (with ``u`` and ``S`` as in
        :mod:`urdsl.kinematics.dh`): shoulder ``|u + d5·S|``, ``L = |a2 + a3·e^{iθ3}|``,
        wrist ``asin|s5|`` and ``|det J| = |a2·a3·s3·s5·(u + d5·S)|``.
        """
        Q = _joint_batch(Q)
        if self.calibration is None:
            return _nominal_singularity(Q, *self._nominal)
        axes, origins = self.axes_many(Q)
        # Factory tables are often "linearized": the three parallel axes get offsets of tens
        # of metres along them that cancel (d2 + d3 + d4 is the arm's d4), and a2, a3 are
        # then not the link lengths. Only points where the arm is are used: the wrist centre,
        # the shoulder (frame 1's origin), wrist 1's axis at frame 4's origin, and the elbow
        # axis's point nearest the shoulder, all seen along the shoulder axis.
        wrist = origins[:, 5]
        lateral = float(np.sum(self._dh[2][1:4]))  # the wrist centre's offset from the base
        r2 = wrist[:, 0] ** 2 + wrist[:, 1] ** 2
        shoulder = np.sqrt(np.maximum(r2 - lateral * lateral, 0.0))
        base, along = origins[:, 1], axes[:, 1]

        def seen_along_shoulder_axis(point: np.ndarray) -> np.ndarray:
            offset = point - base
            return offset - np.sum(offset * along, axis=1)[:, None] * along

        to_shoulder = base - origins[:, 2]
        elbow_point = origins[:, 2] + np.sum(to_shoulder * axes[:, 2], axis=1)[:, None] * \
            axes[:, 2]
        elbow_at = seen_along_shoulder_axis(elbow_point)
        wrist_at = seen_along_shoulder_axis(origins[:, 4])
        a2 = np.linalg.norm(elbow_at, axis=1)
        a3 = np.linalg.norm(wrist_at - elbow_at, axis=1)
        length = np.linalg.norm(wrist_at, axis=1)
        elbow = np.maximum(np.minimum(a2 + a3 - length, length - np.abs(a2 - a3)), 0.0)
        sin_wrist = np.linalg.norm(np.cross(axes[:, 3], axes[:, 5]), axis=1)
        wrist_angle = np.arcsin(np.clip(sin_wrist, 0.0, 1.0))
        flange = origins[:, 6]
        jacobian = np.concatenate(
            [np.cross(axes[:, :6], flange[:, None] - origins[:, :6]), axes[:, :6]], axis=2)
        with np.errstate(divide="ignore", invalid="ignore"):  # LU of an exactly singular J
            manipulability = np.abs(np.linalg.det(jacobian))
        return {"shoulder": shoulder, "elbow": elbow, "wrist": wrist_angle,
                "manipulability": manipulability}


def _nominal_singularity(Q: np.ndarray, d1: float, a2: float, a3: float, d4: float,
                         d5: float, d6: float) -> dict[str, np.ndarray]:
    """:meth:`Robot.singularity` of a nominal arm, in closed form."""
    _, sines, _, big_s, u, v = arm_terms(Q, a2, a3)
    s3, s5 = sines[:, 2], sines[:, 4]
    sideways = u + d5 * big_s
    length = np.sqrt(u * u + v * v)
    reach, fold = abs(a2) + abs(a3), abs(abs(a2) - abs(a3))
    return {"shoulder": np.abs(sideways),
            "elbow": np.maximum(np.minimum(reach - length, length - fold), 0.0),
            "wrist": np.arcsin(np.minimum(np.abs(s5), 1.0)),
            "manipulability": np.abs(a2 * a3 * s3 * s5 * sideways)}
