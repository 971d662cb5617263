"""The UR arms as data: DH tables, joint limits, joint speed limits, reach and payload.

Reading this module needs NumPy only (no Pinocchio), so tools that just list models or check
joint limits stay light. Every UR arm uses *standard* (distal) Denavit–Hartenberg parameters
with the same structure::

    T_i = Rz(θ_i) · Tz(d_i) · Tx(a_i) · Rx(α_i),   i = 1 … 6
    a = (0, a2, a3, 0, 0, 0)      a2, a3 < 0            [m]
    d = (d1, 0, 0, d4, d5, d6)                          [m]
    α = (π/2, 0, 0, π/2, −π/2, 0)                       [rad]

``T_1 · … · T_6`` is the pose of the tool flange (the controller's TCP with a zero TCP offset,
ROS ``tool0``, Z out of the flange) in the controller's Base frame (ROS ``base``, which is ROS
``base_link`` turned by π about z).

Sources
-------
* DH tables of UR3 … UR30 (CB3 and e-Series, UR20, UR30): ``docs/controller-facts.md`` §1,
  i.e. UR's article "DH Parameters for calculations of kinematics and dynamics", the ROS 2
  description ``config/<model>/default_kinematics.yaml`` and
  ``ur_kinematics/src/ur_kin.cpp``, which agree.
* UR7e, UR12e, UR15, UR18, UR8 Long: the DH table of the ``ur-analytic-ik`` package
  (``dh_parameters.hh``, citing the same UR article). UR7e is the UR5e arm and UR12e the UR10e
  arm under the names UR uses since 2025.
* Joint position limits: the controller allows ±2π (±360°) on every joint; wrist 3 of the
  UR3 and UR3e turns without limit (``docs/controller-facts.md`` §2), stored as ±∞.
* Joint speed limits: ROS 2 description ``config/<model>/joint_limits.yaml`` (which cite the
  UR manuals): ``docs/controller-facts.md`` §2 for the first nine models, the UR12e file
  (= UR10e values), the UR18 file (180, 180, 240, 300, 300, 300 °/s). UR7e uses the UR5e
  values. UR15 and UR8 Long use the UR18 values: same joint sizes (identical d1, d4, d5,
  d6) — unconfirmed [U].
* Reach and payload: UR product data sheets as quoted in ``docs/controller-facts.md`` §3
  (UR10e 12.5 kg on newer units); UR7e, UR12e, UR15, UR18 and UR8 Long from one
  third-party table of UR's current line-up [S] (which also rates newer UR20/UR30 units at
  25/35 kg; the original 20/30 kg ratings are kept here).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["ModelSpec", "MODELS", "DH_ALPHA", "model_spec", "JOINT_NAMES", "NOMINAL_ACCURACY"]

JOINT_NAMES = ("base", "shoulder", "elbow", "wrist 1", "wrist 2", "wrist 3")
"""The six joints of every UR arm, from the base out, as PolyScope names them (the URDF of
the robot description calls them ``shoulder_pan_joint`` … ``wrist_3_joint``)."""

NOMINAL_ACCURACY = 0.005
"""How far (m) a real arm's TCP may lie from where the nominal DH table puts it: a factory
calibration moves it by 1-7 mm (the residuals of waypoint pairs taught on real arms, see
:func:`urdsl.verify.infer.infer`)."""

#: The twist angles α_i [rad] shared by every UR arm.
DH_ALPHA = (math.pi / 2, 0.0, 0.0, math.pi / 2, -math.pi / 2, 0.0)

_TWO_PI = 2.0 * math.pi


def _frozen(values) -> np.ndarray:
    array = np.array(values, dtype=float)
    array.setflags(write=False)
    return array


@dataclass(frozen=True, eq=False)
class ModelSpec:
    """One UR arm model as data (all arrays have shape (6,) and are read-only).

    ``dh_a``, ``dh_d`` in m, ``dh_alpha`` in rad (standard DH, θ offsets 0);
    ``q_min``, ``q_max`` joint position limits in rad (±∞ for an unlimited joint);
    ``qd_max`` joint speed limits in rad/s; ``generation`` is ``"cb3"``, ``"e-series"`` or
    ``"ur-series"``; ``reach`` in m; ``payload`` in kg; ``robot_type`` the primary interface's
    ``robotType`` code (docs/controller-facts.md §3; UR7e and UR12e are assumed to report the
    UR5 and UR10 codes of the arms they rename [U]).
    """

    name: str
    dh_a: np.ndarray
    dh_d: np.ndarray
    dh_alpha: np.ndarray
    q_min: np.ndarray
    q_max: np.ndarray
    qd_max: np.ndarray
    generation: str
    reach: float
    payload: float
    robot_type: int = 0

    @property
    def d1(self) -> float:
        return float(self.dh_d[0])

    @property
    def a2(self) -> float:
        return float(self.dh_a[1])

    @property
    def a3(self) -> float:
        return float(self.dh_a[2])

    @property
    def d4(self) -> float:
        return float(self.dh_d[3])

    @property
    def d5(self) -> float:
        return float(self.dh_d[4])

    @property
    def d6(self) -> float:
        return float(self.dh_d[5])

    def __repr__(self) -> str:
        return (f"ModelSpec({self.name!r}, {self.generation}, d1={self.d1}, a2={self.a2}, "
                f"a3={self.a3}, d4={self.d4}, d5={self.d5}, d6={self.d6}, reach={self.reach} m, "
                f"payload={self.payload} kg)")


def _spec(name: str, d1: float, a2: float, a3: float, d4: float, d5: float, d6: float, *,
          speeds_deg: tuple[float, ...], generation: str, reach: float, payload: float,
          robot_type: int = 0, wrist3_unlimited: bool = False) -> ModelSpec:
    q_max = [_TWO_PI] * 6
    if wrist3_unlimited:
        q_max[5] = math.inf
    return ModelSpec(
        name=name,
        dh_a=_frozen([0.0, a2, a3, 0.0, 0.0, 0.0]),
        dh_d=_frozen([d1, 0.0, 0.0, d4, d5, d6]),
        dh_alpha=_frozen(DH_ALPHA),
        q_min=_frozen([-value for value in q_max]),
        q_max=_frozen(q_max),
        qd_max=_frozen([math.radians(value) for value in speeds_deg]),
        generation=generation,
        reach=reach,
        payload=payload,
        robot_type=robot_type,
    )


_SMALL = (180.0, 180.0, 180.0, 360.0, 360.0, 360.0)   # UR3, UR3e
_MEDIUM = (180.0,) * 6                                  # UR5, UR5e, UR7e
_LARGE = (120.0, 120.0, 180.0, 180.0, 180.0, 180.0)    # UR10, UR10e, UR12e, UR16e
_HEAVY = (120.0, 120.0, 150.0, 210.0, 210.0, 210.0)    # UR20, UR30
_NEW = (180.0, 180.0, 240.0, 300.0, 300.0, 300.0)      # UR18 (UR15, UR8 Long [U])

#: Every supported model by its lower-case name.
MODELS: dict[str, ModelSpec] = {
    spec.name: spec
    for spec in (
        _spec("ur3", 0.1519, -0.24365, -0.21325, 0.11235, 0.08535, 0.0819, speeds_deg=_SMALL,
              generation="cb3", reach=0.5, payload=3.0, robot_type=3, wrist3_unlimited=True),
        _spec("ur5", 0.089159, -0.425, -0.39225, 0.10915, 0.09465, 0.0823, speeds_deg=_MEDIUM,
              generation="cb3", reach=0.85, payload=5.0, robot_type=1),
        _spec("ur10", 0.1273, -0.612, -0.5723, 0.163941, 0.1157, 0.0922, speeds_deg=_LARGE,
              generation="cb3", reach=1.3, payload=10.0, robot_type=2),
        _spec("ur3e", 0.15185, -0.24355, -0.2132, 0.13105, 0.08535, 0.0921, speeds_deg=_SMALL,
              generation="e-series", reach=0.5, payload=3.0, robot_type=3,
              wrist3_unlimited=True),
        _spec("ur5e", 0.1625, -0.425, -0.3922, 0.1333, 0.0997, 0.0996, speeds_deg=_MEDIUM,
              generation="e-series", reach=0.85, payload=5.0, robot_type=1),
        _spec("ur10e", 0.1807, -0.6127, -0.57155, 0.17415, 0.11985, 0.11655,
              speeds_deg=_LARGE, generation="e-series", reach=1.3, payload=12.5, robot_type=2),
        _spec("ur16e", 0.1807, -0.4784, -0.36, 0.17415, 0.11985, 0.11655, speeds_deg=_LARGE,
              generation="e-series", reach=0.9, payload=16.0, robot_type=4),
        _spec("ur20", 0.2363, -0.8620, -0.7287, 0.2010, 0.1593, 0.1543, speeds_deg=_HEAVY,
              generation="ur-series", reach=1.75, payload=20.0, robot_type=7),
        _spec("ur30", 0.2363, -0.6370, -0.5037, 0.2010, 0.1593, 0.1543, speeds_deg=_HEAVY,
              generation="ur-series", reach=1.3, payload=30.0, robot_type=8),
        _spec("ur7e", 0.1625, -0.425, -0.3922, 0.1333, 0.0997, 0.0996, speeds_deg=_MEDIUM,
              generation="e-series", reach=0.85, payload=7.5, robot_type=1),
        _spec("ur12e", 0.1807, -0.6127, -0.57155, 0.17415, 0.11985, 0.11655,
              speeds_deg=_LARGE, generation="e-series", reach=1.3, payload=12.5, robot_type=2),
        _spec("ur15", 0.2186, -0.6475, -0.5164, 0.1824, 0.1361, 0.1434, speeds_deg=_NEW,
              generation="ur-series", reach=1.3, payload=17.5, robot_type=9),
        _spec("ur18", 0.2186, -0.475, -0.3389, 0.1824, 0.1361, 0.1434, speeds_deg=_NEW,
              generation="ur-series", reach=0.95, payload=18.0, robot_type=5),
        _spec("ur8long", 0.2186, -0.8989, -0.7149, 0.1824, 0.1361, 0.1434, speeds_deg=_NEW,
              generation="ur-series", reach=1.75, payload=10.0, robot_type=6),
    )
}

# Spellings people use for the same arm ("UR8 Long", "ur8_long", "UR-5e").
_ALIASES = {"ur8_long": "ur8long", "ur8-long": "ur8long", "ur8 long": "ur8long"}


def model_spec(name: str) -> ModelSpec:
    """The :class:`ModelSpec` for ``name`` (case-insensitive, ``"UR5e"``, ``"ur8 long"``).

    Raises :class:`~urdsl.kinematics.errors.KinematicsError` naming the known models.
    """
    from .errors import KinematicsError

    key = str(name).strip().lower()
    key = _ALIASES.get(key, key).replace("-", "")
    if key not in MODELS:
        raise KinematicsError(f"unknown robot model {name!r}; known models: "
                              + ", ".join(MODELS))
    return MODELS[key]
