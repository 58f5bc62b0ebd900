"""Examples: the ones reproducing paper figures equal the built-in study configs and validate."""
import pytest

from conftest import EXAMPLES

from tirecli.studies.configs import builtin_config_names


@pytest.mark.parametrize("name", builtin_config_names())
def test_example_matches_builtin(name):
    from importlib import resources

    ex = EXAMPLES / f"{name}.yaml"
    if not ex.exists():
        pytest.skip(f"{name} has no example copy")
    builtin = resources.files("tirecli.studies").joinpath("configs").joinpath(f"{name}.yaml").read_text()
    assert ex.read_text() == builtin, f"examples/{name}.yaml differs from the built-in study config"


@pytest.mark.parametrize("path", sorted(EXAMPLES.glob("*.yaml")), ids=lambda p: p.name)
def test_every_example_validates(cli, path):
    code, out, err = cli("params", "validate", path)
    assert code == 0, err


def test_a_failed_check_says_what_was_checked(cli, tmp_path):
    """The line of a failed check names what the check means (its description), not only its id, and
    calls the reference of a bound a bound."""
    cfg = tmp_path / "fig1.yaml"
    cfg.write_text((EXAMPLES / "fm-fig1-left.yaml").read_text().replace(
        "tire: canudas2003-table1", "tire: {set: canudas2003-table1, mu_s: 1.6}"))
    code, out, err = cli("sweep", cfg, "--out", tmp_path / "o")
    assert code == 0, err
    lines = [ln for ln in out.splitlines() if ln.startswith("check failed: ")]
    assert lines and all(ln.count(": ") >= 3 and " vs " in ln for ln in lines), lines
    assert any("check failed: fm-fig1-left/peak-v20: peak |mu| at v = 20 m/s: " in ln for ln in lines), lines


@pytest.mark.slow  # long for the default run (CI's 15 min); -m slow runs it
def test_the_monte_carlo_example_says_why_its_checks_fail(cli, tmp_path):
    """campaign-fm-fig4-mc fails its two checks by design: the output says so (the checks' descriptions),
    and docs/campaigns.md shows those lines (here on 24 of its 1000 points)."""
    import re

    from conftest import ROOT

    text = (EXAMPLES / "campaign-fm-fig4-mc.yaml").read_text()
    small = tmp_path / "campaign-fm-fig4-mc.yaml"
    small.write_text(text.replace("base: fm-fig4.yaml", f"base: {EXAMPLES / 'fm-fig4.yaml'}").replace("n: 1000", "n: 24"))
    code, out, err = cli("campaign", small, "--out", tmp_path / "c", "--jobs", "1")
    assert code == 0, err
    failed = [ln for ln in out.splitlines() if ln.startswith("check failed: ")]
    assert len(failed) == 2 and all("fails by design" in ln for ln in failed), out
    docs = (ROOT / "docs" / "campaigns.md").read_text()
    for ln in failed:
        assert re.sub(r": [\d.]+$", "", ln) in docs, ln


@pytest.mark.slow
def test_the_tight_fit_example_fails_only_the_check_it_explains(cli, tmp_path):
    """examples/fm-fig6-tight.yaml: the one failed check (the intervals of a fit to noise-free data are
    narrower than its error) is named in the example and in docs/transient.md (about 30 s)."""
    from conftest import ROOT

    code, out, err = cli("fit", EXAMPLES / "fm-fig6-tight.yaml", "--out", tmp_path / "o")
    assert code == 0, err
    failed = [ln for ln in out.splitlines() if ln.startswith("check failed: ")]
    assert [ln.split(":")[1].strip() for ln in failed] == ["fm-fig6/dist-ci"], failed
    assert failed[0] in (ROOT / "docs" / "transient.md").read_text()
    assert failed[0].split(" (tolerance")[0] in (EXAMPLES / "fm-fig6-tight.yaml").read_text().replace("\n# ", " ")
