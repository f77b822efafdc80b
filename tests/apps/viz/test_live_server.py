"""The live view: a meshcat server on loopback only, serving the page, shut down at the end
of a run and on Ctrl-C, on a configurable port with a clear error when it is taken; and a
run with the view gives exactly the rollout of a run without it."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import numpy as np
import paused_cli
import pytest
from viz_support import SPRING, short_scenario

from uvms_pin.apps.viz.live import LiveView, MeshcatServer, port_is_free, run_live
from uvms_pin.apps.viz.meshcat_scene import Frame
from uvms_pin.errors import PortInUseError
from uvms_pin.results.rollout import Rollout
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.run import simulate

CLI = [str(Path(sys.executable).with_name("uvms-pin"))]


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _listening_addresses(port: int) -> set[str]:
    """Local addresses (hex, as in /proc/net/tcp*) listening on ``port``."""
    found = set()
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        if not os.path.exists(table):
            continue
        for line in Path(table).read_text().splitlines()[1:]:
            fields = line.split()
            address, hex_port = fields[1].rsplit(":", 1)
            if int(hex_port, 16) == port and fields[3] == "0A":  # 0A: LISTEN
                found.add(address)
    return found


def _server_processes(port: int) -> list[int]:
    pids = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            cmd = (entry / "cmdline").read_bytes().split(b"\0")
        except OSError:
            continue
        if any(b"_meshcat_server.py" in c for c in cmd) and str(port).encode() in cmd:
            pids.append(int(entry.name))
    return pids


def test_the_server_listens_on_loopback_only_and_serves_the_page():
    with MeshcatServer(port=0) as server:
        assert server.web_url.startswith("http://127.0.0.1:")
        with urllib.request.urlopen(server.web_url, timeout=10) as response:
            page = response.read().decode()
        assert response.status == 200
        assert "MeshCat" in page and "meshcat-pane" in page
        if os.path.exists("/proc/net/tcp"):
            assert _listening_addresses(server.port) == {"0100007F"}  # 127.0.0.1, no v6
        proc = server.proc
    assert proc.poll() is not None  # terminated
    assert port_is_free(server.port)


def test_a_busy_port_is_a_clear_error():
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        with pytest.raises(PortInUseError, match=f"port {port} on 127.0.0.1 is already in use"):
            MeshcatServer(port=port).start()
        assert _server_processes(port) == []


def test_ctrl_c_inside_a_live_view_shuts_the_server_down(reference_uvms):
    from uvms_pin.apps.viz.meshcat_scene import UvmsScene

    scene = UvmsScene(reference_uvms)
    port = _free_port()
    with pytest.raises(KeyboardInterrupt), LiveView(scene, port=port) as live:
        assert live.url == f"http://127.0.0.1:{port}/static/"
        live.push(Frame(0.0, reference_uvms.neutral_configuration()))
        raise KeyboardInterrupt
    assert port_is_free(port)
    assert _server_processes(port) == []


def test_a_live_run_gives_the_same_rollout_and_frees_the_port(tmp_path):
    """PPC in continuous time on the paper's spring (0.2 s): taps on plant and controller."""
    paper = Path(__file__).resolve().parents[3] / "scenarios" / "paper_force_tracking.toml"
    overrides = {"scenario.duration_s": 0.2}
    plain = simulate(load_scenario(paper, overrides))
    port = _free_port()
    live = run_live(load_scenario(paper, overrides), port=port, speed=50.0, out=None)
    _assert_same(plain, live)
    assert "force_desired_world_N" in live.signals
    assert port_is_free(port)


def test_a_saved_run_is_replayed_one_frame_a_sample(monkeypatch):
    """`replay_live` queues every sample of the rollout, in order, once a browser is there."""
    from uvms_pin.apps.viz import live as live_module

    class _View:
        def __init__(self, scene, **options):
            self.watched, self.error, self.frames, self.finished = True, None, [], False

        def __enter__(self):
            self.__class__.opened = self
            return self

        def __exit__(self, *exc) -> None:
            pass

        def push(self, frame: Frame) -> None:
            self.frames.append(frame)

        def lag_s(self) -> float:
            return 0.0

        def finish(self) -> None:
            self.finished = True

    paper = Path(__file__).resolve().parents[3] / "scenarios" / "paper_force_tracking.toml"
    rollout = simulate(load_scenario(paper, {"scenario.duration_s": 0.1}))
    monkeypatch.setattr(live_module, "LiveView", _View)
    live_module.replay_live(rollout, scene=None, out=None)
    view = _View.opened
    assert view.finished and len(view.frames) == len(rollout)
    desired = rollout.signals["force_desired_world_N"]
    for k, frame in enumerate(view.frames):
        assert frame.time_s == float(rollout.time_s[k])
        np.testing.assert_array_equal(frame.q, rollout.q[k])
        np.testing.assert_array_equal(
            frame.force_measured_world_N, rollout.wrench_measured_world[k, :3]
        )
        np.testing.assert_array_equal(frame.force_desired_world_N, desired[k])


def _assert_same(a: Rollout, b: Rollout) -> None:
    for name in Rollout._BASE:
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    assert a.signals.keys() == b.signals.keys()
    for key in a.signals:
        np.testing.assert_array_equal(a.signals[key], b.signals[key], err_msg=key)


def _run_cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([*CLI, *args], capture_output=True, text=True, timeout=120, check=False)


def test_cli_live_run_equals_plain_run_and_shuts_down(tmp_path):
    scenario = short_scenario(tmp_path, 0.5, extra=SPRING)
    port = _free_port()
    plain = _run_cli("run", str(scenario), "--out", str(tmp_path / "plain"), "--quiet")
    live = _run_cli(
        "run", str(scenario), "--out", str(tmp_path / "live"), "--quiet", "--live",
        "--port", str(port), "--speed", "20", "--html",
    )  # fmt: skip
    assert plain.returncode == 0, plain.stderr
    assert live.returncode == 0, live.stderr
    assert f"live view: http://127.0.0.1:{port}/static/" in live.stdout
    assert port_is_free(port) and _server_processes(port) == []
    _assert_same(Rollout.load(tmp_path / "plain"), Rollout.load(tmp_path / "live"))
    assert (tmp_path / "live" / "replay.html").is_file()


def test_cli_busy_port_exits_with_a_clear_message(tmp_path):
    scenario = short_scenario(tmp_path, 0.5)
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        result = _run_cli(
            "run", str(scenario), "--out", str(tmp_path / "o"), "--live", "--port", str(port)
        )
    assert result.returncode == 2
    assert f"port {port} on 127.0.0.1 is already in use" in result.stderr
    assert "--port" in result.stderr
    assert "Traceback" not in result.stderr


def test_cli_ctrl_c_during_a_live_run_shuts_the_server_down(tmp_path):
    """Ctrl-C while the live run is simulating (held at its 20th sample by a test hook, the
    view streaming): the server is gone when the command returns."""
    scenario = short_scenario(tmp_path, 20.0)
    port = _free_port()
    command = ["run", str(scenario), "--out", str(tmp_path / "o"), "--quiet", "--live",
               "--port", str(port), "--speed", "0.5"]  # fmt: skip
    proc = paused_cli.start(["--pause-at-sample", "20"], command, tmp_path)
    try:
        lines = paused_cli.wait_until_paused(proc)
        assert lines[0].startswith(f"live view: http://127.0.0.1:{port}/static/"), lines
        assert _server_processes(port)
        with urllib.request.urlopen(f"http://127.0.0.1:{port}/static/", timeout=10) as r:
            assert r.status == 200
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 130, err
    assert "interrupted" in err and "Traceback" not in err
    assert port_is_free(port)
    assert _server_processes(port) == []  # terminated and reaped before the command returned


class ManualClock:
    """The live view's clock (its module's ``time``), advanced by the test alone:
    ``perf_counter`` reads it; everything else is the real ``time``."""

    def __init__(self) -> None:
        self.now_s = 0.0

    def perf_counter(self) -> float:
        return self.now_s

    def __getattr__(self, name: str):
        return getattr(time, name)


def test_a_browser_receives_the_stream_paced_by_the_clock(reference_uvms, monkeypatch):
    """A page on the live URL shows the frames as the view's clock plays them: at twice
    real time, 0.5525 s of clock show the frame of t = 1.105 s (x = 0.110 m), 0.4 s more
    the one of t = 1.905 s (x = 0.190 m), not the last one pushed (x = 0.299 m)."""
    from viz_support import HeadlessPage

    from uvms_pin.apps.viz import live as live_module
    from uvms_pin.apps.viz.meshcat_scene import UvmsScene

    clock = ManualClock()
    monkeypatch.setattr(live_module, "time", clock)
    page = HeadlessPage()  # skips without chromium
    # the vehicle's body node (its pieces sit in it at fixed placements)
    base = "viewer.scene_tree.find(['meshcat', 'uvms_pin', 'robot', 'visuals', 'root_joint'])"
    x = f"{base}.object.position.x"
    try:
        with LiveView(UvmsScene(reference_uvms), port=0, speed=2.0) as live:
            q = reference_uvms.neutral_configuration()
            for k in range(300):  # 3 s moving at 0.1 m/s along x
                q_k = q.copy()
                q_k[0] = 0.001 * k
                live.push(Frame(0.01 * k, q_k))
            page.open(live.url, f"{x} === 0")  # the first frame, which the server keeps
            # more than the view's 0.5 s between two looks for a browser: it finds this one
            clock.now_s += 0.5525
            page.wait_until(f"{x} > 0.1")
            assert page.evaluate(x) == pytest.approx(0.110, abs=1e-9)
            clock.now_s += 0.4
            page.wait_until(f"{x} > 0.15")
            assert page.evaluate(x) == pytest.approx(0.190, abs=1e-9)
            assert live.watched and live.shown == 3  # the first frame, then one per advance
            assert page.websockets == [f"ws://127.0.0.1:{live.server.port}/"]
            port = live.server.port
    finally:
        page.close()
    assert port_is_free(port)
