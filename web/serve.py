"""Serves a folder on 127.0.0.1 for the page test (scripts/wasm.sh), and
takes the page's result: a POST to /result is written to RESULT_FILE.
Prints the port it listens on, then serves until killed.

    python3 web/serve.py FOLDER RESULT_FILE
"""
import functools
import http.server
import sys

folder, result_file = sys.argv[1], sys.argv[2]


class Handler(http.server.SimpleHTTPRequestHandler):
    extensions_map = {**http.server.SimpleHTTPRequestHandler.extensions_map, ".wasm": "application/wasm", ".js": "text/javascript"}

    def do_POST(self):
        if self.path != "/result":
            self.send_error(404)
            return
        body = self.rfile.read(int(self.headers.get("Content-Length", 0)))
        with open(result_file, "wb") as f:
            f.write(body)
        self.send_response(204)
        self.end_headers()

    def log_message(self, *args):
        pass


server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), functools.partial(Handler, directory=folder))
print(server.server_address[1], flush=True)
server.serve_forever()
