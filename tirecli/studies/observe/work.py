"""The solver work of an observe run as a sample-budget Estimate, each term blamed on the config keys that
drive it, and the refusal of inputs no adaptive solver can integrate, at their key.

The numbers are :mod:`tirecli.numerics.observer_work`'s; this module only knows where in an observe config
(:mod:`tirecli.studies.observe`) the measurement, the gains, the torque and the adhesion of each case are given.
The plan's sample estimate adds it once the profiles are checked
(:func:`tirecli.studies.observe.planning._sample_estimate` with the plant).
"""
from __future__ import annotations

from tirecli.errors import ConfigError
from tirecli.studies.observe.spec import GAINS


def work_estimate(checked: dict, cases: list, solver, plant, origins):
    """The solver work of every case as an Estimate (each term blamed on the keys that drive it); a
    ConfigError at the gain that no adaptive solver can integrate (:mod:`tirecli.numerics.observer_work`)."""
    from tirecli.limits import Estimate
    from tirecli.numerics import observer_work as ow

    est = Estimate()
    study_gain = (checked["gain_study"] or {}).get("gain")
    for j, case in enumerate(cases):
        env = ow.scenario_envelope(plant, case.scenario)

        def gain(name, j=j):
            return (("cases", j, "observer", name), ("observer", name)) + ((("gain_study", "values"),) if study_gain == name else ())

        torque = (("cases", j, "torque"), ("scenario", "torque"))
        keys = {"torque": torque, "rtol": (("solver", "rtol"),), "v0": (("scenario", "v0"),),
                "theta": (("cases", j, "theta"), ("scenario", "theta"))}
        given = {g for g in GAINS if any(p in origins.where for p in gain(g))}
        bad = ow.injection_problem(plant, case.gains, case.scenario, case.sensor, solver, env, given)
        if bad is not None:
            paths = keys.get(bad[0]) or gain(bad[0]) + (("observer",),)
            raise ConfigError(origins.problem(next((p for p in paths if p in origins.where), paths[-1]), bad[1]))
        keys = {"restarts": (("cases", j, "measurement", "rate"), ("measurement", "rate"), ("solver", "method")),
                "ringing": (torque + gain("gamma")) if env.spin else (gain("gamma") + torque),
                "inputs": torque + (("cases", j, "theta"), ("scenario", "theta"))}
        for kind, work, what in ow.work_terms(plant, case.gains, case.scenario, case.sensor, solver, env,
                                              (case.scenario.torque, case.theta_profile)):
            est.add(work, keys[kind] + (("observer",), ("scenario", "duration")),
                    what if len(cases) == 1 else f"{what} (case {case.label})", 0.0)   # evaluations: nothing stored
    return est


def log_work_estimate(samples: int, cases: int, bytes_per_point: float):
    """The work of an observe run on a measured log (:mod:`tirecli.studies.observe.log`): per case, the log's
    samples recorded (``bytes_per_point`` each) and about :data:`tirecli.numerics.observer_log.CALLS_PER_SAMPLE` solver evaluations a
    sample interval (LSODA restarts at every held sample)."""
    from tirecli.limits import Estimate
    from tirecli.numerics.observer_log import CALLS_PER_SAMPLE

    est = Estimate()
    for _ in range(cases):
        est.add(samples, (("measurement", "log"), ("cases",)), "log samples recorded", bytes_per_point)
        est.add(samples * CALLS_PER_SAMPLE, (("measurement", "log"), ("cases",)),
                "observer evaluations (a restart at every held sample)", 0.0)
    return est
