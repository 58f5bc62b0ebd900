"""A run the solver cannot carry out fails with one line naming its cause (exit 1)."""

CONFIG = """\
study: simulate
tire: canudas2003-table2
initial: {v: 20, slip: 0}
input:
  pressure: {table: {t: [0, 0.5, 2.0, 2.6], value: [0, 0, 50, 0]}}
t_end: 1.0
cases:
  - {model: lumped, kappa0: Z, label: braking}
figures: [transient-histories]
"""


def test_absurd_pressure_gain_names_the_input(cli, tmp_path):
    """A brake torque 1e18 times the tire's underflows the time step: the error names the torque input
    and its size, in one line; a large but finite brake (1e12 N m/bar) still runs (the wheel locks)."""
    cfg = tmp_path / "b.yaml"
    cfg.write_text(CONFIG)
    code, out, err = cli("simulate", cfg, "--set", "input.pressure_gain=1e20", "-o", tmp_path / "o")
    assert code == 1
    line, = err.strip().splitlines()
    # the peak torque: 1e20 N m/bar * 16.7 bar (the pressure at t_end)
    assert "time step underflow at t = 0.5 s" in line and "input.pressure_gain" in line and "1.67e+21 N m" in line
    code, out, err = cli("simulate", cfg, "--set", "input.pressure_gain=1e12", "-o", tmp_path / "o2")
    assert code == 0 and "wheel lock: from 0.5" in out
