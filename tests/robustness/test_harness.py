"""The harness itself: a usage error through the real CLI is one clean line with exit 2."""
from harness import assert_clean_error, run


def test_unknown_option_is_one_line_exit_2():
    r = run(["sweep", "--no-such-option"])
    assert r.code == 2 and "Traceback" not in r.err


def test_missing_config_is_one_line_exit_2(tmp_path):
    r = run(["sweep", tmp_path / "nope.yaml"])
    assert_clean_error(r, 2, r"nope\.yaml")
