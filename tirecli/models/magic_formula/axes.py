"""Axis system and signs of the Magic Formula in tirecli, stated once (docs/models/magic_formula_tyre.md §2).

Internally every Magic Formula quantity is in the **ISO-W** (TYDEX W) contact-patch frame, the
frame of every ``.tir`` file:

- origin at the contact point; ``x`` forward along the wheel plane / road plane intersection,
  ``z`` up (normal to the road), ``y = z x x`` to the left; forces and moments are those the road
  exerts on the tyre;
- ``kappa = -V_sx/|V_cx| = (Omega R_e - V_cx)/|V_cx|`` [-]: > 0 driving, < 0 braking, -1 locked
  wheel. This is the practical slip of :func:`tirecli.conventions.kappa_from_slip` (the LuGre
  slip ``s`` of :mod:`tirecli.conventions` maps to it one to one);
- ``tan(alpha) = V_sy/|V_cx|`` [rad]: a positive slip angle gives a **negative** ``Fy``, so the
  cornering stiffness ``dFy/dalpha`` is negative (``PKY1 < 0`` in ISO files);
- ``gamma`` [rad] > 0 tilts the top of the wheel towards ``-y``; camber thrust is negative for
  ``gamma > 0`` (``PKY6 < 0``);
- ``Mz`` > 0 counter-clockwise seen from above (``Mz = -t Fy > 0`` for small ``alpha > 0``);
  ``My`` < 0 when rolling forwards (rolling resistance); ``Fz`` > 0 in compression.

SAE J670 (x forward, y right, z down) is a rotation by 180 degrees about ``x``:
``alpha_SAE = -alpha``, ``Fy_SAE = -Fy``, ``Fz_SAE = -Fz``, ``My_SAE = -My``, ``Mz_SAE = -Mz``;
``kappa``, ``gamma``, ``Fx`` and ``Mx`` keep their signs (:func:`tirecli.conventions.iso_to_sae`, an
involution; measured data in SAE or adapted ISO are converted by :func:`tirecli.conventions.axes_to_iso`).

Left and right tyres (§2.4): a file is measured on the side given by ``TYRESIDE``. A tyre used
on the other side is its mirror image in the ``x-z`` plane: the inputs ``alpha`` and ``gamma``
change sign, and so do the outputs ``Fy``, ``Mx`` and ``Mz``; ``Fx`` and ``My`` do not
(:func:`mirror_inputs`, :func:`mirror_outputs`). This is the physically consistent mirror the
spec recommends (§10), used for both conventions.
"""
from __future__ import annotations

import numpy as np

# the ISO-W <-> SAE J670 map lives with the other sign conventions (one place); re-exported here
from tirecli.conventions import iso_to_sae, sae_to_iso  # noqa: F401

#: Sides a tyre can be measured on / mounted at.
SIDES = ("left", "right")

#: Outputs whose sign flips under the left/right mirror (§2.4).
MIRRORED_OUTPUTS = ("fy", "mx", "mz")


def normalise_side(text) -> str:
    """``'LEFT'``, ``'Left'``, ``'l'`` ... -> ``'left'``; ``'right'`` likewise; else ``'unknown'``."""
    t = str(text or "").strip().strip("'\"").lower()
    if t in ("left", "l"):
        return "left"
    if t in ("right", "r"):
        return "right"
    return "unknown"


def needs_mirror(file_side: str, mount_side: str | None) -> bool:
    """True when a tyre measured on ``file_side`` is mounted on the other known side."""
    if mount_side is None:
        return False
    return file_side in SIDES and mount_side in SIDES and file_side != mount_side


def mirror_inputs(alpha, gamma):
    """Mirror the slip angle and inclination of a tyre used on the other side: ``(-alpha, -gamma)`` [rad]."""
    return -np.asarray(alpha, dtype=float), -np.asarray(gamma, dtype=float)


def mirror_outputs(out: dict) -> dict:
    """Negate ``fy`` [N], ``mx`` [N m], ``mz`` [N m] of an output mapping in place (§2.4) and return it."""
    for k in MIRRORED_OUTPUTS:
        if k in out and out[k] is not None:
            np.negative(out[k], out=out[k])
    return out

