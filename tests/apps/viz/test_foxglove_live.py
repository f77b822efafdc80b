"""The Foxglove live view (`uvms_pin.apps.viz.foxglove_live`) read by an independent client:
a WebSocket client speaking the Foxglove protocol (advertise, subscribe, binary message
data) whose messages are decoded by rosbags and compared with the rollout they came from,
as the MCAP bag's are (tests/ros_bag_check.py)."""

from __future__ import annotations

import json
import socket
import struct
import threading
import time
from collections import defaultdict
from pathlib import Path

import pytest

pytest.importorskip("foxglove")
pytest.importorskip("rosbags")
from rosbags.typesys import Stores, get_typestore
from websockets.exceptions import ConnectionClosed
from websockets.sync.client import connect

from tests.ros_bag_check import check_bag
from uvms_pin.apps.cli.main import main
from uvms_pin.apps.export.ros_bag import rollout_model
from uvms_pin.apps.export.ros_sample import SampleTopics, records_of
from uvms_pin.apps.viz.foxglove_live import FoxgloveFeed, FoxgloveLive, scenario_topics
from uvms_pin.errors import PortInUseError
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.run import simulate

ROOT = Path(__file__).resolve().parents[3]
_MESSAGE_DATA = 0x01
_STORE = get_typestore(Stores.ROS2_HUMBLE)


class Client(threading.Thread):
    """Connects to ``url`` (retrying until the server is up), subscribes to every channel
    advertised and keeps each message decoded: ``received[topic] = [(log time, msg)]``."""

    def __init__(self, url: str, timeout_s: float = 30.0):
        super().__init__(daemon=True)
        self.url, self.timeout_s = url, timeout_s
        self.received: dict[str, list] = defaultdict(list)
        self.subscribed, self.connected = threading.Event(), threading.Event()
        self.error: BaseException | None = None
        self.advertised: dict[int, dict] = {}

    def run(self) -> None:
        try:
            self._run()
        except BaseException as exc:  # reported by the test
            self.error = exc

    def _run(self) -> None:
        deadline = time.monotonic() + self.timeout_s
        while True:
            try:
                ws = connect(
                    self.url,
                    subprotocols=["foxglove.sdk.v1", "foxglove.websocket.v1"],
                    open_timeout=5,
                )
                break
            except OSError:
                if time.monotonic() > deadline:
                    raise
                time.sleep(0.05)
        self.connected.set()
        with ws:
            subscription_topic: dict[int, tuple[str, str]] = {}
            try:
                for frame in ws:
                    if isinstance(frame, str):
                        self._control(ws, json.loads(frame), subscription_topic)
                    elif frame[0] == _MESSAGE_DATA:
                        sub, time_ns = struct.unpack_from("<IQ", frame, 1)
                        topic, msgtype = subscription_topic[sub]
                        message = _STORE.deserialize_cdr(bytes(frame[13:]), msgtype)
                        self.received[topic].append((time_ns, message))
            except ConnectionClosed:
                pass

    def _control(self, ws, message: dict, subscription_topic: dict) -> None:
        if message.get("op") != "advertise":
            return
        subscriptions = []
        for channel in message["channels"]:
            sub = len(subscription_topic) + 1
            pkg, name = channel["schemaName"].split("/")
            subscription_topic[sub] = (channel["topic"], f"{pkg}/msg/{name}")
            assert channel["encoding"] == "cdr" and channel["schemaEncoding"] == "ros2msg"
            subscriptions.append({"id": sub, "channelId": channel["id"]})
            self.advertised[channel["id"]] = channel
        ws.send(json.dumps({"op": "subscribe", "subscriptions": subscriptions}))
        self.subscribed.set()


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture(scope="module")
def push_rollout():
    """A short run with a free object, fixed objects and an arm (push_object's first 0.2 s)."""
    short = {"scenario.duration_s": 0.2, "output.log_period_s": 0.02}
    scenario = load_scenario(ROOT / "scenarios" / "push_object.toml", short)
    return simulate(scenario, progress=False)


def test_a_client_subscribed_from_the_start_gets_every_message_of_the_bag(push_rollout):
    rollout = push_rollout
    records = list(records_of(rollout))
    topics = SampleTopics(rollout.metadata, rollout_model(rollout))
    with FoxgloveLive(topics, port=0, speed=20.0, out=None) as live:
        live.advertise(records[0])
        client = Client(live.url)
        client.start()
        assert client.subscribed.wait(30.0), client.error
        while not live.all_watched:  # the server has taken the subscriptions
            time.sleep(0.01)
        for record in records:
            live.push(record)
        live.finish()
    client.join(30.0)
    assert client.error is None, client.error
    assert set(client.received) >= {"/tf", "/tf_static", "/joint_states", "/odometry/truth", "/world/markers"}  # fmt: skip
    check_bag(rollout, dict(client.received))  # every message, to 1e-9


def test_a_running_simulation_is_streamed_at_real_time_as_it_runs():
    scenario = load_scenario(ROOT / "scenarios" / "passive_still_water.toml", {"scenario.duration_s": 1.5})  # fmt: skip
    with FoxgloveLive(scenario_topics(scenario), port=0, speed=1.0, out=None) as live:
        client = Client(live.url)  # connects once the first sample starts the server
        client.start()
        start = time.monotonic()
        rollout = simulate(scenario, progress=False, observers=[FoxgloveFeed(live)])
        run_s = time.monotonic() - start
        live.finish()
        wall_s = time.monotonic() - start
    client.join(30.0)
    assert client.error is None, client.error
    assert run_s < 1.0 < 1.5 <= wall_s + 0.05  # the run is not held; the stream is paced
    received = dict(client.received)
    assert len(received["/tf"]) == len(rollout)  # the first sample waited for the subscription
    static = received["/tf_static"]
    assert 1 <= len(static) <= 3  # sent again each second for a late client
    received["/tf_static"] = static[:1]
    check_bag(rollout, received)


def test_uvms_pin_run_live_foxglove_prints_the_address_and_writes_the_run(tmp_path, capsys):
    port = _free_port()
    code = main(
        ["run", str(ROOT / "scenarios" / "passive_still_water.toml"), "--out", str(tmp_path / "run"),
         "--quiet", "--live", "foxglove", "--port", str(port), "--set", "scenario.duration_s=0.5"]
    )  # fmt: skip
    assert code == 0
    assert f"ws://127.0.0.1:{port}" in capsys.readouterr().out
    assert (tmp_path / "run" / "rollout.npz").is_file()


def test_a_port_in_use_is_refused_by_name():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        s.listen()
        port = s.getsockname()[1]
        topics = SampleTopics({}, rollout_model_for_tests())
        with pytest.raises(PortInUseError, match=str(port)):
            FoxgloveLive(topics, port=port, out=None).start()


def rollout_model_for_tests():
    from uvms_pin.model.urdf.load import load_uvms

    return load_uvms(ROOT / "models" / "uvms_bluerov2_alpha5.urdf")


def test_the_cli_refuses_an_unknown_live_viewer(capsys):
    with pytest.raises(SystemExit) as stop:
        main(["run", "scenarios/passive_still_water.toml", "--out", "/tmp/x", "--live", "rviz"])
    assert stop.value.code == 2
    assert "foxglove" in capsys.readouterr().err


def _replayed(rollout, run_dir: Path, speed: float) -> Client:
    """``rollout`` saved in ``run_dir`` and served by `uvms-pin replay --live foxglove` at
    ``speed`` to a `Client`, which has it all when this returns."""
    rollout.save(run_dir)
    port = _free_port()
    client = Client(f"ws://127.0.0.1:{port}")
    client.start()
    code = main(["replay", str(run_dir), "--live", "foxglove", "--port", str(port), "--speed", str(speed)])  # fmt: skip
    client.join(30.0)
    assert code == 0 and client.error is None, client.error
    return client


def test_uvms_pin_replay_live_foxglove_waits_for_a_client_and_sends_the_whole_run(
    push_rollout, tmp_path, capsys
):
    client = _replayed(push_rollout, tmp_path / "run", speed=50)
    assert "waiting for a Foxglove client" in capsys.readouterr().out
    check_bag(push_rollout, dict(client.received))


def test_a_saved_run_with_a_camera_and_a_sonar_is_replayed_with_their_images(tmp_path):
    """`uvms-pin replay --live foxglove` of a seabed survey sends what its bag holds: the
    camera's colour, depth and labels and the sonars' images at their firings, their frames
    in /tf_static (it sent the samples' topics only)."""
    short = {"scenario.duration_s": 0.3}
    rollout = simulate(load_scenario(ROOT / "scenarios" / "seabed_survey.toml", short), progress=False)  # fmt: skip
    assert rollout.perception  # the survey's camera and sonars fired
    client = _replayed(rollout, tmp_path / "run", speed=20)
    kinds = {name: about["kind"] for name, about in rollout.metadata["perception"].items()}
    assert set(kinds.values()) == {"camera", "sonar"}
    for name, kind in kinds.items():
        topic = f"/{name}/image_raw" if kind == "camera" else f"/{name}/image"
        assert topic in client.received, topic
    check_bag(rollout, dict(client.received))  # every message, images bit for bit
