"""The Magic Formula tyre model: MF 6.1 / 6.2, MF 5.2 / PAC2002 and PAC89 (pure, vectorized numpy).

Documentation: ``docs/models/magic_formula_tyre.md`` (sections cited as §N in every docstring). Axis system and
signs: :mod:`.axes` (ISO-W, stated once; the LuGre slip relation is in :mod:`tirecli.conventions`).

- :class:`MFTire` -- coefficients (SI), version, measured side (:mod:`.tire`);
- :func:`evaluate` -- forces and moments over broadcast arrays (:mod:`.engine`);
- :class:`Convention`, :data:`CONVENTIONS` -- the ``mfeval`` (default) and ``teasit`` variants of §10;
- :mod:`.mf61` (the kernel; its equations by concept: :mod:`.curve`, :mod:`.state`, :mod:`.pure`,
  :mod:`.combined`, :mod:`.aligning`, :mod:`.moments`), :mod:`.pac89`, :mod:`.turnslip`, :mod:`.radius`,
  :mod:`.inputs` (§11), :mod:`.check` (coefficient sanity).
"""
from tirecli.models.magic_formula.axes import iso_to_sae, sae_to_iso
from tirecli.models.magic_formula.engine import OUTPUTS, MFResult, evaluate
from tirecli.models.magic_formula.tire import CONVENTIONS, Convention, MFTire, complete_coefficients

__all__ = ["MFTire", "MFResult", "Convention", "CONVENTIONS", "OUTPUTS", "evaluate", "complete_coefficients",
           "iso_to_sae", "sae_to_iso"]
