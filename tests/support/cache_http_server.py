#!/usr/bin/env python3
"""cache_http_server.py — HTTP servers that misbehave, for the shared cook cache's tests.

cook_cache_test starts one on loopback (the real cache server of the tests is nginx with WebDAV);
this one plays the servers a studio's cache must survive:
  store DIR       a Bazel-layout cache over DIR (GET/PUT /ac/<key>, /cas/<key>), like nginx's;
                  with --die-after N it stops answering and exits after N requests (down mid-batch)
  junk            answers every GET with 200 and bytes that are no entry, accepts every PUT
  hang            accepts connections and never answers (a server too slow to wait for)
It binds 127.0.0.1 on a free port and writes the port to --port-file once it listens.
"""
import argparse
import http.server
import os
import socket
import sys
import threading
import time


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("mode", choices=["store", "junk", "hang"])
    ap.add_argument("dir", nargs="?")
    ap.add_argument("--port-file", required=True)
    ap.add_argument("--die-after", type=int, default=0)
    args = ap.parse_args()

    if args.mode == "hang":
        s = socket.socket()
        s.bind(("127.0.0.1", 0))
        s.listen(64)
        publish(args.port_file, s.getsockname()[1])
        held = []
        while True:
            conn, _ = s.accept()
            held.append(conn)  # never read from, never answered, never closed

    served = [0]

    class Handler(http.server.BaseHTTPRequestHandler):
        protocol_version = "HTTP/1.1"

        def log_message(self, *a):
            pass

        def count(self):
            served[0] += 1
            if args.die_after and served[0] > args.die_after:
                os._exit(0)  # gone: the connection drops without an answer, later ones are refused

        def path_on_disk(self):
            parts = self.path.strip("/").split("/")
            if len(parts) != 2 or parts[0] not in ("ac", "cas") or not parts[1].isalnum():
                return None
            return os.path.join(args.dir, parts[0], parts[1])

        def answer(self, status, body=b""):
            self.send_response(status)
            self.send_header("Content-Length", str(len(body)))
            self.end_headers()
            self.wfile.write(body)

        def do_GET(self):
            self.count()
            if args.mode == "junk":
                return self.answer(200, b"<html>this is not a cache entry</html>\n" * 7)
            p = self.path_on_disk()
            if p is None or not os.path.isfile(p):
                return self.answer(404)
            with open(p, "rb") as f:
                self.answer(200, f.read())

        def do_PUT(self):
            self.count()
            body = self.rfile.read(int(self.headers.get("Content-Length", "0")))
            if args.mode == "junk":
                return self.answer(200)
            p = self.path_on_disk()
            if p is None:
                return self.answer(400)
            os.makedirs(os.path.dirname(p), exist_ok=True)
            tmp = p + ".tmp-%d-%d" % (os.getpid(), threading.get_ident())
            with open(tmp, "wb") as f:
                f.write(body)
            os.replace(tmp, p)
            self.answer(201)

    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Handler)
    publish(args.port_file, server.server_address[1])
    server.serve_forever()


def publish(path, port):
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write(str(port))
    os.replace(tmp, path)


if __name__ == "__main__":
    sys.exit(main())
