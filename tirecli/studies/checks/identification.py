"""Reference checks of the identification figures FM Fig. 6 and Table 2: the fits of the synthetic braking
#2 and a fit of exact Table 2 steady-state samples (``docs/models/lugre_friction.md`` §10)."""
from __future__ import annotations

import numpy as np

from tirecli.studies.base import Check

#: Measured deviations of the distributed-model fit from Table 2 on the noise-free synthetic braking #2
#: (fm-fig6 study, data solved at tol 1e-6: 0.03, 3.5e-3, 2.2e-4; the residual there is the data's own
#: numerical error, see the Table 2 caption), with margin.
DIST_TOLERANCE = {"sigma0": 0.15, "sigma1": 0.01, "mu_s": 0.001}


#: Largest error of the output-error fit relative to the generating value (issue 23's target; sigma2, whose
#: generating value is 0, absolute in s/m). Measured on the noise-free 100 Hz lock braking of
#: examples/fm-fig6-output-error.yaml: 2.8e-5 (sigma0), the engine's target test 2.9e-5.
OE_TOLERANCE = 1e-3
OE_SIGMA2_TOLERANCE = 1e-4


def _braking2(result) -> bool:
    """Whether the data are FM's braking #2 of fm-fig4 (the data the FM-procedure references were measured on)."""
    d = (result.payload.get("checked") or {}).get("data") or {}
    return d.get("simulate") == "fm-fig4" and list(d.get("cases") or []) == ["braking #2"]


def oe_checks(result) -> list:
    """The output-error fit against the generating values (FM Table 2) of the synthetic data: each fitted tire
    parameter within :data:`OE_TOLERANCE` relative, and none named not identifiable."""
    from tirecli.studies.fit import TABLE2

    f = result.payload.get("output_error")
    if f is None:
        return []
    src = "FM Table 2 (the generating values of the synthetic data); output error, the quarter car simulated from the brake input"
    out = []
    for k in f.names:
        if k not in TABLE2:
            continue
        if TABLE2[k] == 0.0:
            out.append(Check(f"oe-{k}", f"{k} of the output-error fit against the generating value (absolute)",
                             float(f.estimate[k]), 0.0, OE_SIGMA2_TOLERANCE, "s/m", src))
        else:
            out.append(Check(f"oe-{k}", f"{k} of the output-error fit, relative to the generating value",
                             float(f.estimate[k]) / TABLE2[k], 1.0, OE_TOLERANCE, "-", src))
    named = f.extra.get("not_identifiable") or []
    out.append(Check("oe-identifiable", "parameters the output-error fit names not identifiable"
                                        + (f" ({', '.join(named)})" if named else ""), float(len(named)), 0.0, 0.0,
                     "-", src, bound="max"))
    return out


def fig6_checks(result):
    from tirecli.studies.fit import TABLE2

    st = result.payload["steady"]
    src = "docs/models/lugre_friction.md §10, FM Fig. 6 (fit on the noise-free synthetic braking #2, t <= 2.6 s, |s| > 0.005)"
    out = oe_checks(result)
    if not _braking2(result):  # the FM procedure's references below were measured on braking #2
        return out
    if "sigma0" in st.names:
        out.append(Check("sigma0", "fitted sigma0 [1/m] (well determined)", float(st.estimate["sigma0"]), 178.8, 1.0,
                         "1/m", src))
    if "mu_s" in st.names:
        out.append(Check("mu_s", "fitted mu_s (well determined)", float(st.estimate["mu_s"]), 1.498, 0.01, "-", src))
    out.append(Check("rms", "residual RMS of the steady-state fit: transient bias ~1e-3", st.residual_rms, 0.001, 0.0015,
                     "-", src))
    f = result.payload.get("distributed")
    if f is not None:
        src3 = "Table 2 (the generating values of the synthetic data); distributed model in the loop"
        units = {"sigma0": "1/m", "sigma1": "s/m"}
        for k, tol in DIST_TOLERANCE.items():
            if k in f.names:
                out.append(Check(f"dist-{k}", f"{k} of the distributed-model fit against the generating value",
                                 float(f.estimate[k]), TABLE2[k], tol, units.get(k, "-"), src3))
        outside = [k for k in f.names if k in TABLE2 and not f.ci_low[k] <= TABLE2[k] <= f.ci_high[k]]
        lvl = int(round(100 * f.confidence))
        out.append(Check("dist-ci", f"generating values outside the distributed-model fit's {lvl}% intervals"
                                    + (f" ({', '.join(outside)})" if outside else ""), float(len(outside)), 0.0, 0.0,
                         "-", src3, bound="max"))
        s1 = result.payload.get("sigma1")
        if s1 is not None:
            out.append(Check("dist-rms", "residual RMS of mu(t): distributed-model fit at most the FM procedure's "
                                         "(stage 2, lumped model)", f.residual_rms, s1.residual_rms, 0.0, "-",
                             "no model bias: the data's model in the loop", bound="max"))
    return out


def table2_checks(result):
    """A fit on exact steady-state samples of Table 2 returns Table 2 (docs/models/lugre_friction.md §10, FM Table 2, Fig. 6)."""
    from dataclasses import replace

    from tirecli.models.lugre import mu_ss_uniform
    from tirecli.numerics.identify import fit_steady_state
    from tirecli.studies.fit import TABLE2

    t2 = result.payload["table2"]
    S, V = np.meshgrid(np.linspace(-1.0, -0.005, 40), np.linspace(5.0, 25.0, 9))
    s, v = S.ravel(), V.ravel()
    mu = mu_ss_uniform(v * s, v * (1.0 + s), t2)
    res, _ = fit_steady_state(s, v, mu, replace(result.payload["start"], alpha=t2.alpha))
    out = []
    for k in res.names:
        ref = TABLE2[k]
        if ref == 0.0:
            out.append(Check(f"exact-{k}", f"{k} fitted to exact Table 2 steady-state samples (absolute)",
                             float(res.estimate[k]), 0.0, 1e-6, "s/m", "docs/models/lugre_friction.md §10 (FM Fig. 6)"))
        else:
            out.append(Check(f"exact-{k}", f"{k} fitted to exact Table 2 steady-state samples, relative to Table 2",
                             float(res.estimate[k]) / ref, 1.0, 1e-4, "-", "docs/models/lugre_friction.md §10 (FM Fig. 6)"))
    return out
