"""MCPS tire model (Sorine & Szymanski 2000)."""
