"""The report: self-contained HTML, summary.json with every check, --strict."""
import json

import pytest


@pytest.fixture(scope="module")
def report_dir(tmp_path_factory):
    from tirecli.cli.main import main

    out = tmp_path_factory.mktemp("report")
    assert main(["--quiet", "report", "--out", str(out), "--only", "FM", "--only", "OBS"]) == 0
    return out


def test_report_files(report_dir):
    html = (report_dir / "index.html").read_text()
    summary = json.loads((report_dir / "summary.json").read_text())
    assert summary["n_checks"] == len(summary["checks"]) > 50
    assert summary["n_failed"] == 0
    for fid in ("fm-fig1-left", "fm-fig1-right", "obs-fig1", "fm-fig6-surface", "fm-table1"):
        assert f'id="{fid}"' in html
        assert (report_dir / "figures" / (fid + (".csv" if "table" in fid else ".png"))).exists()
    assert "data:image/png;base64," in html


def test_report_is_self_contained(report_dir):
    import re

    html = (report_dir / "index.html").read_text()
    assert not re.search(r"""(src|href)=["']https?://""", html)
    assert "<script" not in html


def test_report_flags_assumed_values(report_dir):
    html = (report_dir / "index.html").read_text()
    assert "ASSUMED" in html and "Stribeck exponent not printed" in html


def test_strict_fails_when_a_check_drifts(cli, tmp_path, monkeypatch):
    from tirecli.studies.checks import steady

    monkeypatch.setitem(steady._REF_SPEEDS, 20, (1.20, 0.212, 0.6451, 0.8717))  # a drifted reference
    code, out, err = cli("report", "--out", tmp_path, "--only", "fm-fig1-left", "--strict")
    assert code == 1 and "fm-fig1-left/peak-v20" in out + err
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["n_failed"] == 1


@pytest.mark.parametrize("fid", ["fm-fig4", "fm-fig7"])
def test_strict_fails_when_a_transient_study_drifts(cli, tmp_path, monkeypatch, fid):
    """FM Figs. 4-8 carry the braking references of docs/models/lugre_friction.md §7: a drifted scenario (brake torque per bar
    5 % off) must fail them, and --strict must exit 1."""
    from tirecli.report import build

    real = build.builtin_config
    monkeypatch.setattr(build, "builtin_config",
                        lambda name, overrides=(): real(name, list(overrides) + ["input.pressure_gain=21"]))
    code, out, err = cli("report", "--out", tmp_path, "--only", fid, "--strict")
    assert code == 1, out + err
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["n_failed"] >= 1
    assert all(c["id"].startswith(fid + "/") for c in summary["checks"] if not c["passed"])


def test_report_only_takes_papers_in_any_case_and_refuses_unknown_names(cli, tmp_path):
    from tirecli.figures.registry import load_all
    from tirecli.report.build import _select

    assert {f.paper for f in _select(load_all(), ["obs"])} == {"OBS"}
    code, out, err = cli("report", "--out", tmp_path, "--only", "fm-fig1-lef")
    assert code == 2 and "did you mean 'fm-fig1-left'" in err
    assert not (tmp_path / "index.html").exists()


def test_report_summary_contents_and_card_links(report_dir):
    """The summary counts checks per paper, the contents link every card, and each card links its PNG,
    its study's data CSVs and run record (studies/STUDY.json), all present in the report."""
    import re
    from html import unescape

    html = (report_dir / "index.html").read_text()
    summary = json.loads((report_dir / "summary.json").read_text())
    cards = re.findall(r'<article class="card[^"]*" id="([^"]+)"', html)
    assert len(cards) == summary["n_figures"] and len(set(cards)) == len(cards)
    toc = html[html.index('<nav class="toc"'):html.index("</nav>")]
    assert set(re.findall(r'href="#([^"]+)"', toc)) - {"paper-FM", "paper-OBS"} == set(cards)
    for paper in ("FM", "OBS"):
        n = sum(c["id"].split("/")[0] in cards and c["id"].startswith(paper.lower()) for c in summary["checks"])
        assert re.search(rf'href="#paper-{paper}">{paper}</a></td><td class="num">\d+</td>\s*'
                         rf'<td class="num pass">{n}</td>', html)
    assert "Failing checks" not in html  # nothing fails here: see tests/test_report_browser.py
    card = html[html.index('id="fm-fig4"'):]
    card = card[:card.index("</article>")]
    files = re.findall(r'class="files">Files: (.*?)</p>', card)[0]
    links = [unescape(h) for h in re.findall(r'href="([^"#]+)"', files)]
    assert links[0] == "figures/fm-fig4.png" and not any(h.endswith(".svg") for h in links)  # PNG only by default
    assert "data/fm-fig4/measured.csv" in links and links[-1] == "studies/fm-fig4.json"
    assert '<a href="figures/fm-fig4.png" title="open the figure at full size">' in card
    for href in set(re.findall(r'(?:href|src)="([^"#:]+)"', html)):  # every local link resolves
        assert (report_dir / unescape(href)).is_file(), href
