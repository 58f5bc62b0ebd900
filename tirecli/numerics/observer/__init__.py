"""Plant + observer in one simulation: a structured fixed-step scheme, adaptive scipy methods, ``auto``.

By concept (import a name from the module that defines it; this package re-exports nothing):

- :mod:`.scenario` -- ``Scenario`` (profiles, initial states), ``Trajectory`` (the recorded run), the fixed
  scheme's time grid and step profiles;
- :mod:`.fast` -- the structured fixed-step scheme (``simulate_fast``, ``fast_model``, ``StepTooLarge``);
- :mod:`.adaptive` -- the full 7-state system with scipy's ``solve_ivp`` (``scalar_rhs``, ``simulate_adaptive``,
  the LSODA stall guard);
- :mod:`.reference` -- the system composed from the models' right-hand sides (``full_rhs``) and the Radau
  reference (``simulate_reference``);
- :mod:`.method` -- ``solver:`` (``SolverOptions``), the choice of ``auto`` (``choose_method``) and the entry
  point ``simulate``.

**Models the kernels implement:** ``adaptive.scalar_rhs`` inlines ``reference.full_rhs``; ``fast.simulate_fast``
inlines :func:`tirecli.observers.plant.rhs` and :func:`tirecli.observers.observer.rhs` through
``fast.fast_model``. Parity to 1e-12: tests/test_model_parity.py.
"""
