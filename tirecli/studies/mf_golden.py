"""The public golden data of the Magic Formula (docs/models/magic_formula_tyre.md §15.4) as a study: every row
reproduced with the ``teasit`` convention, one reference check per block (the largest residual
against the tolerance 1e-6 N / N m, the print precision of the data).

The rows are those of docs/models/magic_formula_tyre.md §15.4, copied from KMoula30/outlap
``crates/outlap-tire/tests/golden/pacejka_2006_205_60r15/{fx0,fy0_mz,combined,combined_camber}.csv``
(generated with teasit/magic-formula-tyre-library under GNU Octave; data CC-BY-SA-4.0, the numbers
are facts), for the Pacejka (2006) Table A3.1 tyre (built-in ``pacejka2006-205-60r15``).

Config (built in as ``mf-golden``; report only)::

    study: mf-golden
    tire: pacejka2006-205-60r15
    convention: teasit
"""
from __future__ import annotations

import numpy as np

from tirecli.config.loader import Config
from tirecli.config.schema import Map, Raw, Str, collect
from tirecli.studies.base import StudyResult, common_fields
from tirecli.studies.registry import register
from tirecli.studies.study import Lazy, Plan, Study

# kappa, alpha_rad, gamma_rad, fz_n, p_pa, vx_mps, fx_n, fy_n, mz_nm, mx_nm, my_nm (docs/models/magic_formula_tyre.md §15.4, copied
# from KMoula30/outlap crates/outlap-tire/tests/golden/pacejka_2006_205_60r15/*.csv, CC-BY-SA-4.0 data)
GOLDEN = {
    "fx0": """\
-0.15,0,0,2000,220000,16.67,-2454.789881,-163.6411509,-34.24337069,0,-6.26
0,0,0,2000,220000,16.67,-114.5334541,20.90991048,-5.335080564,0,-6.26
0.03,0,0,2000,220000,16.67,977.4660065,126.1319875,8.965539804,0,-6.26
0.09,0,0,2000,220000,16.67,2191.276563,206.0867675,27.49964628,0,-6.26
0.15,0,0,2000,220000,16.67,2450.690818,191.902705,31.78587536,0,-6.26
0.3,0,0,2000,220000,16.67,2277.776872,134.568265,30.07213503,0,-6.26
-0.15,0,0,4000,220000,16.67,-4837.649514,-167.3415256,-66.91405564,0,-12.52
0,0,0,4000,220000,16.67,-172.0094611,42.00044636,-11.32558474,0,-12.52
0.03,0,0,4000,220000,16.67,2233.419392,157.4861513,22.09031303,0,-12.52
0.09,0,0,4000,220000,16.67,4516.362632,242.9226944,57.60092987,0,-12.52
0.15,0,0,4000,220000,16.67,4839.604625,224.1087646,63.35152795,0,-12.52
0.3,0,0,4000,220000,16.67,4391.07609,155.4577919,58.27506941,0,-12.52""",
    "fy0_mz": """\
0,-0.084,0,2000,220000,16.67,-77.50329094,1779.957807,-21.74256282,0,-6.26
0,0.0105,0,2000,220000,16.67,-111.9493809,-256.041834,-0.9853385911,0,-6.26
0,0.042,0,2000,220000,16.67,-95.30455754,-1007.626856,9.46346945,0,-6.26
0,0.084,0,2000,220000,16.67,-69.47185887,-1639.609431,11.66389292,0,-6.26
0,0.147,0,2000,220000,16.67,-42.776985,-1949.290859,4.798332809,0,-6.26
0,0.21,0,2000,220000,16.67,-27.38732579,-2006.056707,0.01818198794,0,-6.26
0,-0.084,0,4000,220000,16.67,-116.3965535,3217.709141,-74.45864437,0,-12.52
0,0.0105,0,4000,220000,16.67,-168.1286296,-438.816506,3.635828161,0,-12.52
0,0.042,0,4000,220000,16.67,-143.1309805,-1787.245403,40.24745993,0,-12.52
0,0.084,0,4000,220000,16.67,-104.33473,-3016.577643,48.95772197,0,-12.52
0,0.147,0,4000,220000,16.67,-64.24364128,-3655.379973,21.76276893,0,-12.52
0,0.21,0,4000,220000,16.67,-41.13103189,-3770.833167,2.325187217,0,-12.52
0,0,-0.06981317008,4000,220000,16.67,-172.0094611,298.4070726,14.43501152,0,-12.52
0,0.042,-0.06981317008,4000,220000,16.67,-143.1309805,-1536.449936,67.10076447,0,-12.52
0,0.084,-0.06981317008,4000,220000,16.67,-104.33473,-2825.287933,74.4599996,0,-12.52
0,0.147,-0.06981317008,4000,220000,16.67,-64.24364128,-3615.557914,37.84952244,0,-12.52""",
    "combined": """\
-0.25,-0.17,0,4000,220000,16.67,-3563.509474,2203.153893,-39.36321111,0,-12.52
-0.1,0.102,0,4000,220000,16.67,-3228.969873,-2922.957587,-40.55411641,0,-12.52
-0.05,0.136,0,4000,220000,16.67,-1636.029361,-3541.718361,-6.77807309,0,-12.52
0.05,0.068,0,4000,220000,16.67,2484.914109,-2402.289342,59.18035787,0,-12.52
0.1,0.034,0,4000,220000,16.67,4349.523184,-1034.154623,59.66406817,0,-12.52
0.25,0.17,0,4000,220000,16.67,3450.343003,-2000.887769,34.47427631,0,-12.52""",
    "combined_camber": """\
-0.1,0.102,-0.06981317008,4000,220000,16.67,-3228.969873,-2760.248592,-32.59451589,0,-12.52
0.05,0.068,-0.06981317008,4000,220000,16.67,2484.914109,-2235.494474,75.87749138,0,-12.52
-0.1,0.102,0.06981317008,4000,220000,16.67,-3228.969873,-3279.314013,-46.39796357,0,-12.52
0.05,0.068,0.06981317008,4000,220000,16.67,2484.914109,-2655.457264,48.30154784,0,-12.52""",
}
TOLERANCE = 1e-6  # N and N m: the print precision of the golden CSVs (docs/models/magic_formula_tyre.md §15.2)
COLUMNS = ("kappa", "alpha", "gamma", "fz", "p", "vx", "fx", "fy", "mz", "mx", "my")
OUTPUTS = ("fx", "fy", "mz", "mx", "my")
BLOCK_TITLES = {
    "fx0": "pure longitudinal slip (alpha = gamma = 0), 2000 and 4000 N",
    "fy0_mz": "pure lateral slip (kappa = 0), 2000 and 4000 N, camber 0 and -4 deg",
    "combined": "combined slip at 4000 N, gamma = 0",
    "combined_camber": "combined slip at 4000 N, camber +-4 deg",
}


def golden_rows(block: str) -> np.ndarray:
    """The rows of one golden block as an array with the columns :data:`COLUMNS`."""
    return np.array([[float(x) for x in line.split(",")] for line in GOLDEN[block].splitlines()])


SPEC = Map(fields=common_fields() | {
    "tire": Raw(doc="the tyre of the golden data (built-in pacejka2006-205-60r15)"),
    "convention": Str(choices=("mfeval", "teasit"), default="teasit", doc="convention (teasit reproduces the data)"),
})


def plan(config: Config) -> Plan:
    """Check a golden-data config (set ``tire``; detail the :class:`~tirecli.models.magic_formula.tire.MFTire`)."""
    from tirecli.parameters.sets import resolve_tire

    checked, tire = collect(lambda: config.checked(SPEC),
                            lambda: resolve_tire(config.data.get("tire"), config.origins, ("tire",), config.base_dir))
    ps, t = tire
    return Plan("mf-golden", config, checked, {"tire": ps}, None, t)


def run(plan_: Plan, progress=None) -> StudyResult:
    """Evaluate every golden row; frame ``golden`` with inputs, golden and computed outputs, residuals."""
    import pandas as pd  # once the config is checked: a refused run fails at once

    from tirecli.models.magic_formula import evaluate

    config, checked, ps, t = plan_.config, plan_.checked, plan_.sets["tire"], plan_.detail

    frames = []
    for block in GOLDEN:
        g = golden_rows(block)
        r = evaluate(t, g[:, 0], g[:, 1], g[:, 2], g[:, 3], g[:, 5], g[:, 4], convention=checked["convention"])
        df = pd.DataFrame({c: g[:, i] for i, c in enumerate(COLUMNS[:6])})
        df.insert(0, "block", block)
        df.insert(1, "row", np.arange(1, len(g) + 1))
        for i, c in enumerate(OUTPUTS):
            df[f"{c}_golden"] = g[:, 6 + i]
            df[f"{c}_tirecli"] = getattr(r, c)
            df[f"{c}_residual"] = getattr(r, c) - g[:, 6 + i]
        frames.append(df)
    return StudyResult(
        study="mf-golden", config=config, parameter_sets={"tire": ps},
        data={"golden": pd.concat(frames, ignore_index=True)},
        meta={"convention": checked["convention"], "tolerance": TOLERANCE, "source": "docs/models/magic_formula_tyre.md §15.4",
              "title": checked["title"] or "Magic Formula golden rows (docs/models/magic_formula_tyre.md §15.4)"},
        figures=checked["figures"] or [f"mf-golden-{b.replace('_', '-')}" for b in GOLDEN],
    )


STUDY = register(Study(
    name="mf-golden", command="report", spec=SPEC, plan=plan, run=run,  # the report's golden-data cards
    figures=tuple(f"mf-golden-{b.replace('_', '-')}" for b in GOLDEN),
    checks={f"mf-golden-{b.replace('_', '-')}": Lazy("tirecli.studies.checks.magic_formula", "golden_checks", (b,))
            for b in GOLDEN},
))
