"""The live view's server process: meshcat's ZMQ/websocket bridge on ONE host and port.

meshcat's own ``meshcat-server`` serves HTTP on every interface and silently moves to the
next port when its port is taken. This script binds the web server to ``--host`` (the
loopback interface) and exactly ``--port`` (0: any free port), prints ``zmq_url=...`` and
``web_url=...`` and serves until terminated or until its parent process is gone. It also
answers ``viewers`` (the number of connected browsers), so that nothing is streamed to
nobody.
Run as a script by `uvms_pin.apps.viz.live` (it imports only meshcat and tornado).
"""

from __future__ import annotations

import argparse
import os
import sys

import tornado.httpserver
import tornado.ioloop
import tornado.netutil
import tornado.web
from meshcat.servers.zmqserver import (
    VIEWER_HTML,
    VIEWER_ROOT,
    StaticFileHandlerNoCache,
    WebSocketHandler,
    ZMQWebSocketBridge,
)


class _LoopbackApp(tornado.web.Application):
    bind_host = "127.0.0.1"
    bound_port = 0

    def listen(self, port, address=None, **kwargs):  # meshcat calls listen(port)
        sockets = tornado.netutil.bind_sockets(port, address=self.bind_host)
        server = tornado.httpserver.HTTPServer(self, **kwargs)
        server.add_sockets(sockets)
        type(self).bound_port = sockets[0].getsockname()[1]
        return server


class _Bridge(ZMQWebSocketBridge):
    def handle_zmq(self, frames):
        # one command more than meshcat's: how many browsers are connected now
        if frames[0] == b"viewers":
            self.zmq_socket.send(str(len(self.websocket_pool)).encode())
            return
        super().handle_zmq(frames)

    def make_app(self):
        return _LoopbackApp(
            [
                (
                    r"/static/(.*)",
                    StaticFileHandlerNoCache,
                    {"path": VIEWER_ROOT, "default_filename": VIEWER_HTML},
                ),
                (r"/", WebSocketHandler, {"bridge": self}),
            ]
        )


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--host", default="127.0.0.1")
    parser.add_argument("--port", type=int, required=True)
    args = parser.parse_args()
    _LoopbackApp.bind_host = args.host
    try:
        bridge = _Bridge(host=args.host, port=args.port)
    except OSError as exc:
        print(f"cannot listen on {args.host}:{args.port}: {exc}", file=sys.stderr)
        return 3
    bridge.fileserver_port = _LoopbackApp.bound_port
    bridge.web_url = f"http://{args.host}:{bridge.fileserver_port}/static/"
    print(f"zmq_url={bridge.zmq_url}", flush=True)
    print(f"web_url={bridge.web_url}", flush=True)

    parent = os.getppid()

    def exit_if_orphaned() -> None:
        if os.getppid() != parent:
            tornado.ioloop.IOLoop.current().stop()

    tornado.ioloop.PeriodicCallback(exit_if_orphaned, 1000).start()
    try:
        bridge.run()
    except KeyboardInterrupt:
        pass
    return 0


if __name__ == "__main__":
    sys.exit(main())
