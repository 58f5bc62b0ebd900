"""Reference checks: what a result must show against the values of ``docs/models/``.

A check function takes a :class:`~tirecli.studies.base.StudyResult` and returns a list of
:class:`~tirecli.studies.base.Check`; it computes what it needs from the result (frames, meta,
payload, parameter sets) and may call models and solvers. Figures draw only; each study's registry
entry lists the checks of its figures by figure id (``Study.checks``, through
:class:`~tirecli.studies.study.Lazy` so that only the checks of the figures drawn are imported),
and the application layer runs them for the figures a config asks for.

One module per family of figures (``steady``, ``transient``, ``identification``, ``observer``,
``magic_formula``, ``mcps``). A module imports at its top only what is cheap (numpy,
:mod:`tirecli.studies.base`, the reading helpers of its study).
"""
