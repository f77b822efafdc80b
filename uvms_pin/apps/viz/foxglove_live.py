"""Live view in Foxglove: the running simulation served over the Foxglove WebSocket protocol
(``foxglove-sdk``, the ``foxglove`` extra) on the loopback interface, with the topics and
ROS 2 messages of the MCAP export (`uvms_pin.apps.export.ros_sample`): Foxglove, or any
client of the protocol, subscribes to ``/tf``, ``/joint_states``, ``/odometry/truth``, ...
as it would to a robot.

The simulation only appends each logged sample to a queue (an observer, `FoxgloveFeed`: the
run is the same with or without the view); a publishing thread sends them at ``speed`` x
real time, never ahead of the simulation (the first one waits up to 1 s for a connected
client to subscribe to the topics it advertises), and sends ``/tf_static`` and ``/world/markers``
again every second so that a client connecting late still has the static frames. When the
run ends, what is left is sent to a subscribed client (at once if none is subscribed), then
the server stops; on Ctrl-C it stops at once.
"""

from __future__ import annotations

import collections
import socket
import sys
import threading
import time
from collections.abc import Iterator
from typing import TYPE_CHECKING, TextIO

from uvms_pin.apps.export.ros_encoding import TopicEncoder
from uvms_pin.apps.export.ros_sample import (
    TOPIC_TYPES,
    Message,
    SampleRecord,
    SampleTopics,
    record_of_sample,
    records_of,
)
from uvms_pin.apps.viz.live import LOOPBACK, port_is_free
from uvms_pin.apps.viz.watched import play_saved, simulate_watched
from uvms_pin.errors import LiveServerError, OptionalDependencyError, PortInUseError
from uvms_pin.results.progress import Progress
from uvms_pin.sim.log import run_metadata
from uvms_pin.sim.run import Scenario

if TYPE_CHECKING:
    from uvms_pin.apps.export.ros_bag import SavedRunTopics
    from uvms_pin.results.rollout import Rollout
    from uvms_pin.sim.sample import Sample

__all__ = [
    "DEFAULT_FOXGLOVE_PORT",
    "FoxgloveFeed",
    "FoxgloveLive",
    "replay_foxglove",
    "run_foxglove",
    "scenario_topics",
]

#: Foxglove's own default port for a WebSocket connection
DEFAULT_FOXGLOVE_PORT = 8765
_STATIC_EVERY_S = 1.0
# how long the first sample waits for subscriptions to every topic: a client already connected
# (Foxglove reconnects on its own) subscribes when the first sample advertises the topics, one
# subscription after the other (Foxglove to those its panels show: it then waits the whole 1 s)
_FIRST_SUBSCRIPTION_S = 1.0
# how long a watched server is kept after the last message so its queues reach the client
_FLUSH_S = 0.5


def _any_free_port(host: str) -> int:
    with socket.socket() as s:
        s.bind((host, 0))
        return int(s.getsockname()[1])


def _sdk():
    try:
        import foxglove
        from foxglove.websocket import ServerListener
    except ImportError as exc:
        raise OptionalDependencyError(
            'the Foxglove live view needs foxglove-sdk: pip install "uvms-pin[foxglove]"'
        ) from exc
    return foxglove, ServerListener


class FoxgloveLive:
    """A Foxglove WebSocket server on ``host:port`` fed with the samples of a run.

    Args:
        topics: the run's messages (`SampleTopics`).
        port: TCP port; 0 picks a free one (`port` holds the one bound after `start`).
        speed: playback speed over real time (> 0).
        out: where the server's address is printed (None: nowhere).

    Raises (from `start`): OptionalDependencyError without foxglove-sdk, PortInUseError,
    LiveServerError.
    """

    def __init__(
        self,
        topics: SampleTopics,
        *,
        port: int = DEFAULT_FOXGLOVE_PORT,
        speed: float = 1.0,
        host: str = LOOPBACK,
        out: TextIO | None = sys.stdout,
    ):
        if not 0 <= int(port) <= 65535:
            raise LiveServerError(f"port must be in 0..65535, got {port}")
        if not speed > 0:
            raise LiveServerError(f"speed must be > 0, got {speed}")
        self.topics, self.port, self.speed, self.host, self.out = (
            topics,
            int(port),
            speed,
            host,
            out,
        )
        # a saved run's cameras and sonars have topics of their own (`SavedRunTopics`)
        self.encoder = TopicEncoder(getattr(topics, "types", TOPIC_TYPES))
        self.error: BaseException | None = None
        self._queue: collections.deque[SampleRecord] = collections.deque()
        self._wake = threading.Condition()
        self._done = self._abort = False
        self._subscriptions: collections.Counter[int] = collections.Counter()  # by channel id
        self._static: list[Message] = []
        self._channels: dict = {}
        self._channels_lock = threading.Lock()
        self._server = self._context = self._thread = self._foxglove = None
        self._clock: tuple[float, float] | None = None  # (wall, simulated) at the first sample

    # ---- server -------------------------------------------------------------------------------
    def start(self) -> FoxgloveLive:
        """Check the port and start the publishing thread; the server itself starts when
        the run's topics are known (`advertise`): a client that connects then is told of
        every channel at once, never of one it cannot subscribe to yet."""
        self._foxglove, self._listener_base = _sdk()
        if self.port == 0:
            self.port = _any_free_port(self.host)
        if not port_is_free(self.port, self.host):
            raise PortInUseError(self.host, self.port)
        self._context = self._foxglove.Context()
        self._thread = threading.Thread(target=self._publish_loop, name="foxglove-live", daemon=True)  # fmt: skip
        self._thread.start()
        if self.out is not None:
            print(
                f"live view: Foxglove WebSocket at {self.url} (in Foxglove: Open connection, "
                "Foxglove WebSocket, this address)",
                file=self.out,
            )
            self.out.flush()
        return self

    def _serve(self) -> None:
        live = self

        class _Listener(self._listener_base):
            def on_subscribe(self, client, channel) -> None:
                with live._wake:
                    live._subscriptions[channel.id] += 1
                    live._wake.notify_all()

            def on_unsubscribe(self, client, channel) -> None:
                with live._wake:
                    live._subscriptions[channel.id] -= 1

        try:
            self._server = self._foxglove.start_server(
                name="uvms-pin",
                host=self.host,
                port=self.port,
                context=self._context,
                server_listener=_Listener(),
            )
        except RuntimeError as exc:  # the SDK's error for a port it cannot bind
            if "in use" in str(exc).lower():
                raise PortInUseError(self.host, self.port) from exc
            raise LiveServerError(f"the Foxglove server did not start: {exc}") from exc

    @property
    def url(self) -> str:
        return f"ws://{self.host}:{self.port}"

    @property
    def watched(self) -> bool:
        """Whether a client is subscribed to at least one topic."""
        return any(n > 0 for n in self._subscriptions.values())

    @property
    def all_watched(self) -> bool:
        """Whether every topic advertised has a subscriber."""
        with self._channels_lock:
            ids = [channel.id() for channel in self._channels.values()]
        return all(self._subscriptions[i] > 0 for i in ids)

    def __enter__(self) -> FoxgloveLive:
        return self.start()

    def __exit__(self, exc_type, exc, tb) -> None:
        self.close(at_once=exc_type is not None)

    # ---- feeding ------------------------------------------------------------------------------
    def advertise(self, record: SampleRecord) -> None:
        """Make the static messages and a channel for every topic the run has (those of its
        first sample ``record``), so that a client can subscribe before anything is sent.
        Called before the publishing thread has anything to send (it shares the topics'
        kinematics)."""
        self._static = list(self.topics.static(record.time_s, record.q))
        for topic, _, _ in [*self._static, *self.topics.at(record)]:
            self._channel(topic)
        self._serve()

    def push(self, record: SampleRecord) -> None:
        """Queue one sample (the first one advertises the run's topics, if not done)."""
        if not self._static:
            self.advertise(record)
        with self._wake:
            self._queue.append(record)
            self._wake.notify_all()

    def finish(self) -> None:
        """Send what is left to a subscribed client (nothing waits without one), then stop."""
        with self._wake:
            self._done = True
            self._wake.notify_all()
        if self._thread is not None:
            while self._thread.is_alive():
                self._thread.join(timeout=0.1)  # a join that Ctrl-C can interrupt
        if self.watched:  # the server sends from its own queues: stopping drops what is left
            time.sleep(_FLUSH_S)
        self.close(at_once=True)

    def close(self, *, at_once: bool = False) -> None:
        """Stop publishing and stop the server (idempotent)."""
        with self._wake:
            self._done = True
            self._abort = self._abort or at_once
            self._wake.notify_all()
        thread, self._thread = self._thread, None
        if thread is not None and thread is not threading.current_thread():
            thread.join(timeout=5.0)
        server, self._server = self._server, None
        if server is not None:
            server.stop()

    def lag_s(self) -> float:
        """Simulated time queued but not yet sent [s]."""
        with self._wake:
            if len(self._queue) < 2:
                return 0.0
            return self._queue[-1].time_s - self._queue[0].time_s

    # ---- the publishing thread ----------------------------------------------------------------
    def _publish_loop(self) -> None:
        try:
            last_static = -float("inf")
            while True:
                record = self._next()
                if record is None:
                    return
                if time.monotonic() - last_static >= _STATIC_EVERY_S:
                    self._send(iter(self._static))
                    last_static = time.monotonic()
                self._send(self.topics.at(record))
        except BaseException as exc:  # reported by the caller; the simulation goes on
            self.error = exc

    def _next(self) -> SampleRecord | None:
        """The next sample once its time has come (``speed`` x real time from the first),
        None when the run is over and nothing is left to send (or nobody listens)."""
        with self._wake:
            while not self._queue:
                if self._done or self._abort:
                    return None
                self._wake.wait(timeout=0.2)
            if self._abort or (self._done and not self.watched):
                return None
            record = self._queue[0]
            if self._clock is None:  # a connected client subscribes once it sees the topics
                subscribe_by = time.monotonic() + _FIRST_SUBSCRIPTION_S
                while not (self.all_watched or self._abort) and time.monotonic() < subscribe_by:  # fmt: skip
                    self._wake.wait(timeout=0.05)
                self._clock = (time.monotonic(), record.time_s)
            wall0, sim0 = self._clock
            due = wall0 + (record.time_s - sim0) / self.speed
            while time.monotonic() < due and not self._abort:
                self._wake.wait(timeout=min(0.05, max(due - time.monotonic(), 0.0)))
            if self._abort:
                return None
            return self._queue.popleft()

    def _send(self, messages: Iterator[Message]) -> None:
        for topic, message, time_ns in messages:
            self._channel(topic).log(self.encoder.encode(topic, message), log_time=time_ns)

    def _channel(self, topic: str):
        """The channel of ``topic``, advertised to the clients when first asked for."""
        with self._channels_lock:
            channel = self._channels.get(topic)
            if channel is None:
                name, text = self.encoder.schema(topic)
                schema = self._foxglove.Schema(name=name, encoding="ros2msg", data=text.encode())
                channel = self._foxglove.Channel(
                    topic, schema=schema, message_encoding="cdr", context=self._context
                )
                self._channels[topic] = channel
            return channel


class FoxgloveFeed:
    """An observer of the closed loop queueing every logged sample on a `FoxgloveLive`."""

    def __init__(self, live: FoxgloveLive):
        self.live = live
        self.kinds = live.topics.joint_kinds

    def on_sample(self, sample: Sample) -> None:
        self.live.push(record_of_sample(sample, self.kinds))


def scenario_topics(scenario: Scenario) -> SampleTopics:
    """The messages a run of ``scenario`` will have, known before it starts (its model's
    links and joints, its world, its thrusters)."""
    metadata = run_metadata(scenario.plant, scenario.settings)
    metadata["world"] = scenario.plant.record()
    return SampleTopics(metadata, scenario.uvms)


def run_foxglove(
    scenario: Scenario,
    *,
    port: int = DEFAULT_FOXGLOVE_PORT,
    speed: float = 1.0,
    progress: Progress | None = None,
    out: TextIO | None = sys.stdout,
) -> Rollout:
    """Simulate a scenario while serving it to Foxglove; the server is gone when this
    returns. A run that stops early is sent to its end and the error re-raised."""
    with FoxgloveLive(scenario_topics(scenario), port=port, speed=speed, out=out) as live:
        return simulate_watched(scenario, live, FoxgloveFeed(live), progress=progress, out=out)


def replay_foxglove(
    rollout: Rollout,
    topics: SampleTopics | SavedRunTopics,
    *,
    port: int = DEFAULT_FOXGLOVE_PORT,
    speed: float = 1.0,
    out: TextIO | None = sys.stdout,
) -> None:
    """Serve a saved rollout to Foxglove at ``speed`` x real time, once a client has
    subscribed (it waits for one); with `SavedRunTopics`, its cameras' and sonars' images
    too, as its bag has them."""
    if len(rollout) == 0:
        raise LiveServerError("the rollout has no sample to serve")
    records = list(records_of(rollout))
    with FoxgloveLive(topics, port=port, speed=speed, out=out) as live:
        live.advertise(records[0])
        play_saved(live, "a Foxglove client to subscribe", records, out)
