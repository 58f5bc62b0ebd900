"""Check every point of a campaign before anything runs (as its command would, without running it).

Large campaigns are checked on a process pool of the campaign's workers (:mod:`tirecli.campaign.execute`).
"""
from __future__ import annotations

import json

import numpy as np

from tirecli.campaign.spec import Campaign, document_hash, inputs_digest, point_config, point_id
from tirecli.errors import ConfigError, Problem, UsageError
from tirecli.io.files import note_input


#: A campaign with at least this many points is checked on ``jobs`` processes.
PARALLEL_CHECK = 2000
_CHECKING = None


def check_points(campaign: Campaign, jobs: int = 1) -> tuple[list, str]:
    """Check every point's config as its command would (:func:`tirecli.app.plan.plan_config`)
    without running it; returns ``(point ids, study name)``. All problems of all points are raised
    together as one ConfigError (each distinct problem once, with how many points have it). Large
    campaigns are checked on ``jobs`` processes (Linux)."""
    global _CHECKING
    import sys

    design = campaign.design
    n = len(design.points)
    if jobs > 1 and n >= PARALLEL_CHECK and sys.platform.startswith("linux"):
        import multiprocessing
        from concurrent.futures import ProcessPoolExecutor

        from tirecli.campaign.execute import pool_options

        bounds = np.linspace(0, n, 4 * jobs + 1).astype(int)
        _CHECKING = campaign  # inherited by the forked workers
        try:
            with ProcessPoolExecutor(jobs, mp_context=multiprocessing.get_context("fork"), **pool_options(None)) as pool:
                parts = list(pool.map(_check_range_global, zip(bounds[:-1], bounds[1:])))
        finally:
            _CHECKING = None
    else:
        parts = [_check_range(campaign, 0, n)]
    hashes, studies, seen, read = [], set(), {}, set()
    for h, st, problems, files in parts:
        hashes += h
        studies |= st
        read |= files
        for k, pts in problems.items():
            seen.setdefault(k, []).extend(pts)
    if seen:
        problems = []
        for (file, line, key, msg), pts in list(seen.items())[:20]:
            where = "" if len(pts) == n else f" (in {len(pts)} of {n} points, e.g. point {pts[0]}: " \
                + ", ".join(f"{k} = {_short(v)}" for k, v in zip(design.keys, design.points[pts[0]])) + ")"
            problems.append(Problem(file, line, key, msg + where))
        raise ConfigError(problems)
    if len(studies) > 1:
        raise ConfigError(campaign.origins.problem(("base",), f"the points run different studies: {', '.join(sorted(studies))}"))
    for path in read:  # also those read by the workers that checked: no output may overwrite them
        note_input(path)
    digest = inputs_digest(read, exclude={campaign.label})
    return [point_id(h, digest) for h in hashes], studies.pop()


def _check_range_global(bounds):
    return _check_range(_CHECKING, int(bounds[0]), int(bounds[1]))


def _check_range(campaign: Campaign, lo: int, hi: int):
    """Check points ``lo`` to ``hi - 1``: ``(document hashes, studies, {problem: [points]}, files read)``."""
    from tirecli.app.plan import plan_config
    from tirecli.io.files import tracked_inputs

    hashes, studies, seen = [], set(), {}
    with tracked_inputs() as read:
        for i in range(lo, hi):
            h = None
            try:
                cfg = point_config(campaign.base, campaign.fixed + campaign.point_overrides(campaign.design.points[i]))
                studies.add(plan_config(cfg).study)
                h = document_hash(cfg)
            except ConfigError as err:
                for p in err.problems:
                    seen.setdefault((p.file, p.line, p.key, p.message), []).append(i)
            except UsageError as err:
                seen.setdefault((campaign.label, None, "", str(err)), []).append(i)
            hashes.append(h)
    return hashes, studies, seen, set(read)


def _short(v) -> str:
    text = json.dumps(v) if not isinstance(v, float) else f"{v:.6g}"
    return text if len(text) <= 40 else text[:37] + "..."


__all__ = ["check_points", "PARALLEL_CHECK"]
