"""Live view: a meshcat server on the loopback interface, fed while the rollout is computed.

The simulation thread only appends a copy of each logged sample to a list (no I/O, no
sleep); a display thread shows them in the browser, paced at ``speed`` x real time and
never ahead of the simulation, and sends nothing while no browser is connected (a browser
that connects gets the current frame). When the run ends the display plays what is left
to a connected browser, then the server is shut down; on Ctrl-C (KeyboardInterrupt) it is
shut down at once.

The logged samples reach the view as an observer of the closed loop (`LiveFeed`): the
simulation is the same with or without it.
"""

from __future__ import annotations

import bisect
import os
import selectors
import socket
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import TextIO

import meshcat
import numpy as np
import zmq
from meshcat.visualizer import ViewerWindow

from uvms_pin.apps.viz.meshcat_scene import (
    EnvironmentView,
    Frame,
    SceneStyle,
    UvmsScene,
    tip_position,
)
from uvms_pin.apps.viz.surface import surface_view_of
from uvms_pin.apps.viz.watched import play_saved, simulate_watched
from uvms_pin.apps.viz.world_view import WorldView
from uvms_pin.errors import LiveServerError, PortInUseError
from uvms_pin.results.progress import Progress
from uvms_pin.results.rollout import Rollout
from uvms_pin.sim.run import Scenario, simulate
from uvms_pin.sim.sample import Sample

LOOPBACK = "127.0.0.1"
DEFAULT_PORT = 7000
_SERVER_SCRIPT = Path(__file__).with_name("_meshcat_server.py")
_LAUNCH = "import runpy, sys; sys.argv[:] = sys.argv[1:]; runpy.run_path(sys.argv[0], run_name='__main__')"
_TRAIL_POINTS = 2000


def port_is_free(port: int, host: str = LOOPBACK) -> bool:
    """Whether a server could listen on ``host:port`` now (as tornado binds: SO_REUSEADDR)."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            s.bind((host, port))
        except OSError:
            return False
    return True


class MeshcatServer:
    """meshcat's ZMQ/websocket bridge in a subprocess, listening on ``host:port`` only.

    Args:
        port: TCP port of the web page; 0 picks a free one.
        host: interface; the loopback interface by default (the page is not exposed).
        startup_timeout_s: how long to wait for the server to report its URLs.

    Raises (from `start`): PortInUseError, LiveServerError.
    """

    def __init__(self, port: int = DEFAULT_PORT, host: str = LOOPBACK, startup_timeout_s=30.0):
        if not 0 <= int(port) <= 65535:
            raise LiveServerError(f"port must be in 0..65535, got {port}")
        self.port = int(port)
        self.host = host
        self.startup_timeout_s = startup_timeout_s
        self.proc: subprocess.Popen | None = None
        self.web_url = ""
        self.zmq_url = ""

    def start(self) -> MeshcatServer:
        if self.port and not port_is_free(self.port, self.host):
            raise PortInUseError(self.host, self.port)
        self._stderr = tempfile.TemporaryFile()
        self.proc = subprocess.Popen(
            [
                sys.executable,
                "-u",
                "-I",
                "-c",
                _LAUNCH,
                str(_SERVER_SCRIPT),
                "--host",
                self.host,
                "--port",
                str(self.port),
            ],
            stdin=subprocess.DEVNULL,
            stdout=subprocess.PIPE,
            stderr=self._stderr,
            start_new_session=True,  # Ctrl-C in the terminal reaches us, not the server
        )
        try:
            urls = self._read_urls()
        except BaseException:
            self.close()
            raise
        self.zmq_url, self.web_url = urls["zmq_url"], urls["web_url"]
        self.port = int(self.web_url.rsplit(":", 1)[1].split("/")[0])
        return self

    def _read_urls(self) -> dict[str, str]:
        assert self.proc is not None and self.proc.stdout is not None
        fd = self.proc.stdout.fileno()
        urls: dict[str, str] = {}
        buffer = b""
        deadline = time.monotonic() + self.startup_timeout_s
        with selectors.DefaultSelector() as sel:
            sel.register(fd, selectors.EVENT_READ)
            while len(urls) < 2:
                left = deadline - time.monotonic()
                if left <= 0:
                    raise LiveServerError(
                        f"the meshcat server did not start within {self.startup_timeout_s:g} s"
                    )
                if not sel.select(timeout=min(left, 0.5)):
                    if self.proc.poll() is not None:
                        self._raise_exited()
                    continue
                chunk = os.read(fd, 4096)
                if not chunk:  # end of file: the server is gone
                    self.proc.wait(timeout=5)
                    self._raise_exited()
                buffer += chunk
                *lines, buffer = buffer.split(b"\n")
                for line in lines:
                    key, _, value = line.decode("utf-8", "replace").strip().partition("=")
                    if key in ("zmq_url", "web_url"):
                        urls[key] = value
        return urls

    def _raise_exited(self) -> None:
        self._stderr.seek(0)
        err = self._stderr.read().decode("utf-8", "replace").strip()
        if "in use" in err.lower():
            raise PortInUseError(self.host, self.port)
        raise LiveServerError(
            f"the meshcat server exited with code {self.proc.returncode}: {err[-2000:]}"
        )

    @property
    def running(self) -> bool:
        return self.proc is not None and self.proc.poll() is None

    def close(self) -> None:
        """Terminate the server (idempotent); its port is free when this returns."""
        proc, self.proc = self.proc, None
        if proc is None:
            return
        if proc.poll() is None:
            proc.terminate()
            try:
                proc.wait(timeout=5)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
        if proc.stdout is not None:
            proc.stdout.close()
        self._stderr.close()

    def __enter__(self) -> MeshcatServer:
        return self.start()

    def __exit__(self, *exc) -> None:
        self.close()


class _Window(ViewerWindow):
    """meshcat's client window on an existing server, with timeouts (never hangs)."""

    def __init__(self, zmq_url: str, web_url: str, timeout_ms: int = 10_000):
        self.server_proc = None
        self.zmq_url = zmq_url
        self.web_url = web_url
        self.timeout_ms = timeout_ms
        self.connect_zmq()

    def connect_zmq(self) -> None:
        self.zmq_socket = self.context.socket(zmq.REQ)
        self.zmq_socket.setsockopt(zmq.LINGER, 0)
        self.zmq_socket.setsockopt(zmq.RCVTIMEO, self.timeout_ms)
        self.zmq_socket.setsockopt(zmq.SNDTIMEO, self.timeout_ms)
        self.zmq_socket.connect(self.zmq_url)

    def viewers(self) -> int:
        """Number of browsers connected to the server now."""
        self.zmq_socket.send(b"viewers")
        return int(self.zmq_socket.recv())

    def close(self) -> None:
        self.zmq_socket.close(linger=0)


class LiveView:
    """Stream frames of a run to a browser through a loopback meshcat server.

    Use as a context manager; `push` from the simulation (cheap, never blocks), `finish` to
    play what is left, leaving the block shuts the server down.

    Args:
        scene: what to draw. port: web port (0: any free). speed: playback speed-up over
        real time (> 0). fps: display refresh rate [Hz]. out: where the URL is printed.
    """

    def __init__(
        self,
        scene: UvmsScene,
        *,
        port: int = DEFAULT_PORT,
        speed: float = 1.0,
        fps: float = 30.0,
        out: TextIO | None = None,
    ):
        if not speed > 0.0:
            raise LiveServerError(f"speed must be positive, got {speed}")
        self.scene = scene
        self.server = MeshcatServer(port)
        self.speed = float(speed)
        self.period_s = 1.0 / fps
        self.out = out
        self._frames: list[Frame] = []
        self._times: list[float] = []
        self._done = threading.Event()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._window: _Window | None = None
        self.error: BaseException | None = None
        self.shown = 0  # frames sent to the viewer
        self.watched = False  # a browser is connected

    @property
    def url(self) -> str:
        return self.server.web_url

    def start(self) -> LiveView:
        self.server.start()
        try:
            self._window = _Window(self.server.zmq_url, self.server.web_url)
            self.vis = meshcat.Visualizer(window=self._window)
            self.scene.build(self.vis)
        except BaseException:
            self.close()
            raise
        if self.out is not None:
            print(f"live view: {self.url}  ({self.scene.legend()})", file=self.out)
            self.out.flush()
        self._thread = threading.Thread(target=self._display, name="uvms-live", daemon=True)
        self._thread.start()
        return self

    def push(self, frame: Frame) -> None:
        """Queue one frame (from the simulation thread): an append, nothing else."""
        self._frames.append(frame)
        self._times.append(frame.time_s)

    def lag_s(self) -> float:
        """Simulated time still to be shown."""
        return (self._times[-1] - self._shown_t) if self._times else 0.0

    def finish(self) -> None:
        """No more frames: wait until the display has shown the last one."""
        self._done.set()
        while self._thread is not None and self._thread.is_alive():
            self._thread.join(timeout=0.2)  # short joins: Ctrl-C stays responsive

    def close(self) -> None:
        """Stop the display and shut the server down (idempotent)."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=5)
            self._thread = None
        if self._window is not None:
            self._window.close()
            self._window = None
        self.server.close()

    def __enter__(self) -> LiveView:
        return self.start()

    def __exit__(self, *exc) -> None:
        self.close()

    # ---- display thread ----------------------------------------------------------------
    _shown_t = 0.0

    def _display(self) -> None:
        shown = -1  # index of the frame on screen
        last_wall = None
        tips: list[np.ndarray] = []
        last_trail = 0.0
        watched, last_poll = False, -np.inf
        self.watched = False
        try:
            while not self._stop.is_set():
                n = len(self._times)
                now = time.perf_counter()
                if now - last_poll > 0.5:  # nobody watching: pace, but send nothing
                    last_poll = now
                    was_watched, watched = watched, self._window.viewers() > 0
                    self.watched = watched
                    if watched and not was_watched:
                        shown = -1  # a new viewer: draw the current frame and trail
                if n:
                    if last_wall is None:
                        self._shown_t = self._times[0]
                    else:
                        step = (now - last_wall) * self.speed
                        self._shown_t = min(self._shown_t + step, self._times[n - 1])
                    last_wall = now
                    idx = max(0, bisect.bisect_right(self._times, self._shown_t, 0, n) - 1)
                    # the first frame always goes (the server caches it for late viewers)
                    if idx != shown and (watched or self.shown == 0):
                        # counted before it is sent: a viewer may draw it (and whoever
                        # watches the viewer look at `shown`) before show() returns here
                        self.shown += 1
                        self.scene.show(self.vis, self._frames[idx])
                        for frame in self._frames[len(tips) : idx + 1]:
                            tips.append(self.scene.ee_position(frame.q))
                        if now - last_trail > 0.25 or idx == n - 1 or shown == -1:
                            self._send_trail(tips[: idx + 1])
                            last_trail = now
                    shown = idx if watched else -1
                    if self._done.is_set() and (idx == len(self._times) - 1 or not watched):
                        return  # shown to the end, or nobody to show it to
                elif self._done.is_set():
                    return
                self._stop.wait(self.period_s)
        except Exception as exc:  # the view failing must never stop the simulation
            self.error = exc

    def _send_trail(self, tips: list[np.ndarray]) -> None:
        if not tips:
            return
        step = max(1, len(tips) // _TRAIL_POINTS)
        points = np.array([*tips[::step], tips[-1]])
        self.vis["uvms_pin/trail"].set_object(self.scene.trail_object(points))


# ---- feeding a live view from a simulation -----------------------------------------------


class LiveFeed:
    """An observer of the closed loop pushing every logged sample to a live view (the world's
    contacts and free objects from the sample's signals, as the rollout logs them)."""

    def __init__(self, live: LiveView):
        self.live = live

    def on_sample(self, sample: Sample) -> None:
        desired = sample.signals.get("force_desired_world_N")
        desired = getattr(desired, "values", desired)  # an array, or a named `Signal`
        contacts = sample.signals.get("world_contact")
        free = sample.signals.get("free_objects")
        objects = sample.signals.get("free_object_contact")
        self.live.push(
            Frame(
                sample.time_s,
                np.array(sample.q),
                sample.measurement.wrench_world[:3].copy(),
                None if desired is None else desired.copy(),
                None if contacts is None else contacts.copy(),
                None if free is None else free.copy(),
                None if objects is None else objects.copy(),
                # every signal by name: the scene draws the fixtures' (named after them)
                {k: np.asarray(getattr(s, "values", s)) for k, s in sample.signals.items()},
            )
        )


def scene_for_scenario(
    scenario: Scenario, style: SceneStyle | None = None, show: str = "visual"
) -> UvmsScene:
    """The scene of a scenario before it runs (extent: the initial vehicle and tip); ``show``
    the robot's visual geometry, its collision shapes or both (`UvmsScene`)."""
    tip0 = tip_position(scenario.uvms, scenario.uvms.model.createData(), scenario.q0)
    controller = scenario.raw.get("controller") or {}
    extent = np.vstack([scenario.q0[:3], tip0])
    surface = surface_view_of(scenario.plant.flow, scenario.plant.free_surface, scenario.q0[:2])
    if surface is not None:  # keep the surface above the vehicle in view
        extent = np.vstack([extent, [*scenario.q0[:2], 0.0]])
    return UvmsScene(
        scenario.uvms,
        environment=EnvironmentView.from_record(
            None if scenario.plant.contact is None else scenario.plant.contact.record(), tip0
        ),
        current_world_m_s=scenario.plant.current_world_m_s,
        show_desired=controller.get("type") == "ppc",
        extent_world_m=extent,
        style=style,
        surface=surface,
        world=WorldView.from_record(scenario.plant.record()["world"], extent.mean(axis=0)),
        show=show,
    )


def simulate_live(
    scenario: Scenario, live: LiveView, *, progress: Progress | None = None
) -> Rollout:
    """`uvms_pin.sim.run.simulate`, with every logged sample pushed to ``live`` (an observer:
    the rollout is the same as without the view)."""
    return simulate(scenario, progress=progress, observers=[LiveFeed(live)])


def run_live(
    scenario: Scenario,
    *,
    port: int = DEFAULT_PORT,
    speed: float = 1.0,
    progress: Progress | None = None,
    out: TextIO | None = sys.stdout,
    style: SceneStyle | None = None,
    show: str = "visual",
) -> Rollout:
    """Simulate a scenario while showing it live; the server is gone when this returns.

    A run that stops early (FunnelViolation, SimulationError) is shown to its end and the
    error re-raised; KeyboardInterrupt closes the view at once and propagates.
    """
    scene = scene_for_scenario(scenario, style, show)
    with LiveView(scene, port=port, speed=speed, out=out) as live:
        return simulate_watched(scenario, live, LiveFeed(live), progress=progress, out=out)


def replay_live(
    rollout: Rollout,
    scene: UvmsScene,
    *,
    port: int = DEFAULT_PORT,
    speed: float = 1.0,
    out: TextIO | None = sys.stdout,
) -> None:
    """Play a saved rollout in a live view at ``speed`` x real time, once a browser is
    connected (it waits for one)."""
    with LiveView(scene, port=port, speed=speed, out=out) as live:
        play_saved(live, "a browser to connect", _frames_of(rollout), out)


def _frames_of(rollout: Rollout) -> Iterator[Frame]:
    """The frames of a saved rollout, one a sample (its time [s], q, measured force [N], and
    the desired force, world contacts and free objects it recorded)."""
    desired = rollout.signals.get("force_desired_world_N")
    contacts = rollout.signals.get("world_contact")
    free = rollout.signals.get("free_objects")
    object_contact = rollout.signals.get("free_object_contact")
    for k in range(len(rollout)):
        yield Frame(
            float(rollout.time_s[k]),
            rollout.q[k],
            rollout.wrench_measured_world[k, :3],
            None if desired is None else desired[k],
            None if contacts is None else contacts[k],
            None if free is None else free[k],
            None if object_contact is None else object_contact[k],
        )
