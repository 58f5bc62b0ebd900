"""Studies: combine models, numerics and parameter sets into runs (no file I/O, no plotting).

Every study is one registry entry, a :class:`~tirecli.studies.study.Study` (name, command, config
schema, ``plan``, ``run``, facts with units, summary lines, default figures and their reference
checks, ...), registered when its module is imported; :data:`tirecli.studies.registry.STUDY_MODULES`
names the module of each built-in study, so a command imports only the study it runs (start-up time).
The commands, the report, campaigns and the Python API use only the entries
(:mod:`tirecli.studies.registry`); ``docs/development.md`` walks through adding a study.

- :mod:`~tirecli.studies.base`: the result (:class:`~tirecli.studies.base.StudyResult`), reference checks
  (:class:`~tirecli.studies.base.Check`), the config keys of every study;
- :mod:`~tirecli.studies.study`, :mod:`~tirecli.studies.registry`: the shape and the registry;
  :mod:`~tirecli.studies.facts`: flat facts and their units; :mod:`~tirecli.studies.configs`: the report's
  study configs (package data, and those registered at runtime);
- the studies: :mod:`~tirecli.studies.sweep` (LuGre, and Magic Formula through :mod:`~tirecli.studies.mf_sweep`),
  :mod:`~tirecli.studies.simulate`, :mod:`~tirecli.studies.fit`, :mod:`~tirecli.studies.observe`,
  :mod:`~tirecli.studies.mcps` (four studies), :mod:`~tirecli.studies.mf_eval` (on
  :mod:`~tirecli.studies.mf_points`, shared with ``tirecli mf eval``), :mod:`~tirecli.studies.mf_golden`;
- :mod:`~tirecli.studies.checks`: the reference checks of the figures, one module per family.
"""
