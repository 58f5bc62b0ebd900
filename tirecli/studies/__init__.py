"""Studies: combine models, numerics and parameter sets into runs (no file I/O, no plotting).

Each study module registers itself in :data:`tirecli.studies.base.STUDIES` when imported;
:data:`tirecli.studies.base.STUDY_MODULES` names the module of each study, so a command imports
only the study it runs (start-up time) and :func:`tirecli.studies.base.load_all_studies` imports
them all.
"""
