"""``campaign --scheduler`` is never silently ignored (issue 24, item 3): an address that cannot be read, a
scheme that is not Dask's, a port that refuses, and a port that answers but not as a Dask scheduler are each
exit 2 within a few seconds, naming the address (the corpus has the first ones; here the servers that answer)."""
from __future__ import annotations

import socket
import threading
from pathlib import Path

import pytest

from harness import assert_clean_error, run

ROOT = Path(__file__).resolve().parents[2]
CAMPAIGN = (ROOT / "examples" / "campaign-obs-convergence.yaml").read_text(encoding="utf-8").replace(
    "base: obs-gain-study.yaml", "base: obs-gain-study")


@pytest.fixture
def listener():
    """A TCP port that accepts connections and then says ``banner`` (nothing: the kernel's backlog accepts)."""
    servers = []

    def make(banner: bytes | None):
        srv = socket.socket()
        srv.bind(("127.0.0.1", 0))
        srv.listen(8)
        servers.append(srv)
        if banner is not None:
            def serve():
                while True:
                    try:
                        conn, _ = srv.accept()
                    except OSError:
                        return
                    conn.sendall(banner)
                    servers.append(conn)
            threading.Thread(target=serve, daemon=True).start()
        return srv.getsockname()[1]

    yield make
    for s in servers:
        s.close()


@pytest.mark.parametrize("banner, why", [(None, r"no Dask handshake within \d+ s"),
                                         (b"SSH-2.0-OpenSSH_9.6\r\n", r"its first bytes are no Dask handshake"),
                                         (b"HTTP/1.1 400 Bad Request\r\n\r\n", r"its first bytes are no Dask handshake")],
                         ids=["silent", "ssh", "http"])
def test_a_port_that_answers_but_not_as_a_dask_scheduler(tmp_path, listener, banner, why):
    pytest.importorskip("distributed")
    port = listener(banner)
    (tmp_path / "c.yaml").write_text(CAMPAIGN)
    r = run(["campaign", "c.yaml", "--out", "o", "--scheduler", f"tcp://127.0.0.1:{port}"], cwd=tmp_path, timeout=60)
    assert_clean_error(r, 2, rf"--scheduler 'tcp://127\.0\.0\.1:{port}': something answers there, but not a Dask scheduler \({why}\)")
    assert not (tmp_path / "o").exists()


def test_a_dask_scheduler_passes_the_check():
    pytest.importorskip("distributed")
    from distributed import LocalCluster

    from tirecli.campaign.execute import check_scheduler

    with LocalCluster(n_workers=0, processes=False, protocol="tcp", dashboard_address=None) as cluster:
        address = cluster.scheduler_address
        assert check_scheduler(address) == address
        assert check_scheduler(address.replace("tcp://", "")) == address  # HOST:PORT means tcp


def test_without_dask_a_scheduler_is_one_line_naming_the_extra(monkeypatch):
    from conftest import block_module

    from tirecli.campaign.execute import check_scheduler
    from tirecli.errors import UsageError

    block_module(monkeypatch, "distributed", "dask")
    for address in ("local", "tcp://127.0.0.1:1"):
        with pytest.raises(UsageError, match=r"--scheduler needs dask, which is not installed: pip install .*\[campaign\]"):
            check_scheduler(address)
    with pytest.raises(UsageError, match="expected 'local'"):  # the address is read first
        check_scheduler("foo")
