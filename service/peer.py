"""``python -m service.peer``: one more HTTP process of ``gearengine serve --http-processes N``
(``service.server.serve_peer``; its socket and settings come in the environment)."""

from service.server import serve_peer

if __name__ == "__main__":
    serve_peer()
