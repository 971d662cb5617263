"""Per-robot DH corrections, as the controller stores them after factory calibration.

Every UR arm is calibrated at the factory; the controller's forward kinematics
(``get_forward_kin``, the TCP pose it reports) uses the corrected table::

    θ_i → θ_i + δθ_i,   a_i → a_i + δa_i,   d_i → d_i + δd_i,   α_i → α_i + δα_i

so a nominal model differs from the real robot by up to a few mm (``docs/controller-facts.md`` §1).
The corrections reach urdsl in two ways:

* the primary interface's KINEMATICS_INFO package carries the *calibrated* DH values
  (``DHtheta``, ``DHa``, ``DHd``, ``DHalpha``; UR's ROS driver builds its DH chain from them
  directly): :meth:`Calibration.from_kinematics_info` subtracts the nominal table;
* a small TOML file (:meth:`Calibration.from_toml`)::

      # DH corrections of robot 20235500123, added to the nominal ur5e table
      model = "ur5e"                        # optional; checked when the file is used
      [delta]                               # corrections (any table may be left out = 0)
      theta = [0.0, 1.2e-4, -3e-5, 0.0, 2e-5, 0.0]    # rad
      a     = [0.0, 2.1e-4, 1.5e-4, 0.0, 0.0, 0.0]    # m
      d     = [1.1e-4, 0.0, 0.0, -8e-5, 5e-5, 0.0]    # m
      alpha = [0.0, 1e-4, 0.0, 0.0, 0.0, 0.0]         # rad

  or, with ``[dh]`` instead of ``[delta]``, the calibrated values themselves (as KINEMATICS_INFO
  sends them; ``model`` is then required).
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .errors import KinematicsError
from .models import ModelSpec, model_spec

__all__ = ["Calibration"]

_FIELDS = ("theta", "a", "d", "alpha")


def _vector(values, name: str) -> np.ndarray:
    if values is None:
        array = np.zeros(6)
    else:
        try:
            array = np.array(values, dtype=float).reshape(-1)
        except (TypeError, ValueError) as error:
            raise KinematicsError(f"calibration {name} must be 6 numbers: {error}") from None
    if array.shape != (6,) or not np.all(np.isfinite(array)):
        raise KinematicsError(f"calibration {name} must be 6 finite numbers, got {values!r}")
    array.setflags(write=False)
    return array


@dataclass(frozen=True, eq=False)
class Calibration:
    """DH corrections per joint: ``delta_theta`` and ``delta_alpha`` in rad, ``delta_a`` and
    ``delta_d`` in m (each (6,), read-only, zeros when left out). ``model`` optionally names
    the model the corrections belong to; :class:`~urdsl.kinematics.Robot` refuses to apply
    them to another one."""

    delta_theta: np.ndarray = None  # type: ignore[assignment]
    delta_a: np.ndarray = None  # type: ignore[assignment]
    delta_d: np.ndarray = None  # type: ignore[assignment]
    delta_alpha: np.ndarray = None  # type: ignore[assignment]
    model: str | None = None

    def __post_init__(self) -> None:
        for field in _FIELDS:
            name = f"delta_{field}"
            object.__setattr__(self, name, _vector(getattr(self, name), name))
        if self.model is not None:
            object.__setattr__(self, "model", model_spec(self.model).name)

    @property
    def is_zero(self) -> bool:
        """True when every correction is exactly zero (the nominal model)."""
        return not any(np.any(getattr(self, f"delta_{field}")) for field in _FIELDS)

    def dh(self, spec: ModelSpec) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The corrected table ``(theta_offset, a, d, alpha)`` of ``spec`` (each (6,))."""
        if self.model is not None and self.model != spec.name:
            raise KinematicsError(f"calibration is for a {self.model}, not a {spec.name}")
        return (self.delta_theta.copy(), spec.dh_a + self.delta_a, spec.dh_d + self.delta_d,
                spec.dh_alpha + self.delta_alpha)

    @classmethod
    def from_kinematics_info(cls, model: str | ModelSpec, dh_theta, dh_a, dh_d,
                             dh_alpha) -> Calibration:
        """Corrections from the calibrated DH values of the primary interface's
        KINEMATICS_INFO package (θ, α in rad; a, d in m) for a robot of ``model``."""
        spec = model if isinstance(model, ModelSpec) else model_spec(model)
        theta, a, d, alpha = (_vector(v, n) for v, n in
                              ((dh_theta, "DHtheta"), (dh_a, "DHa"), (dh_d, "DHd"),
                               (dh_alpha, "DHalpha")))
        calibration = cls(theta, a - spec.dh_a, d - spec.dh_d, alpha - spec.dh_alpha,
                          model=spec.name)
        largest = max(float(np.max(np.abs(calibration.delta_a))),
                      float(np.max(np.abs(calibration.delta_d))))
        if largest > 0.05:
            raise KinematicsError(
                f"these DH values differ from the nominal {spec.name} by {largest:.3f} m: "
                "not a calibration of this model (wrong model?)")
        return calibration

    @classmethod
    def from_toml(cls, path: str | Path, model: str | None = None) -> Calibration:
        """Read a calibration file (format in the module docstring). ``model`` is needed for
        a ``[dh]`` file that does not name its model itself."""
        path = Path(path)
        try:
            data = tomllib.loads(path.read_text(encoding="utf-8"))
        except OSError as error:
            raise KinematicsError(f"{path}: cannot read calibration: {error.strerror}") from None
        except tomllib.TOMLDecodeError as error:
            raise KinematicsError(f"{path}: not valid TOML: {error}") from None
        return cls.from_mapping(data, model=model, source=str(path))

    @classmethod
    def from_mapping(cls, data: dict, model: str | None = None,
                     source: str = "calibration") -> Calibration:
        """A calibration from the parsed TOML mapping (see :meth:`from_toml`)."""
        unknown = set(data) - {"model", "delta", "dh"}
        if unknown:
            raise KinematicsError(f"{source}: unknown keys {sorted(unknown)}; expected model, "
                                  "[delta] or [dh]")
        name = data.get("model", model)
        if model is not None and name is not None and model_spec(model).name != \
                model_spec(name).name:
            raise KinematicsError(f"{source}: file is for a {name}, not a {model}")
        if ("delta" in data) == ("dh" in data):
            raise KinematicsError(f"{source}: give exactly one of the tables [delta] or [dh]")
        table = data.get("delta", data.get("dh"))
        if not isinstance(table, dict) or set(table) - set(_FIELDS):
            raise KinematicsError(f"{source}: the table may hold only {', '.join(_FIELDS)}")
        if "delta" in data:
            return cls(*(table.get(field) for field in _FIELDS), model=name)
        if name is None:
            raise KinematicsError(f"{source}: a [dh] table needs model = \"...\"")
        missing = [field for field in _FIELDS if field not in table]
        if missing:
            raise KinematicsError(f"{source}: [dh] lacks {', '.join(missing)}")
        return cls.from_kinematics_info(name, *(table[field] for field in _FIELDS))

    def to_toml(self) -> str:
        """This calibration as a ``[delta]`` TOML document (read back by :meth:`from_toml`)."""
        lines = ["# urdsl DH corrections (theta, alpha in rad; a, d in m)"]
        if self.model:
            lines.append(f'model = "{self.model}"')
        lines.append("[delta]")
        for field in _FIELDS:
            values = ", ".join(repr(float(v)) for v in getattr(self, f"delta_{field}"))
            lines.append(f"{field} = [{values}]")
        return "\n".join(lines) + "\n"
