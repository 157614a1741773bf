"""hapticjam-web: a browser viewer of hapticjam-server (docs/web.md).

A small HTTP gateway that serves the pages in clients/web/static/ and turns
their JSON requests into calls of the server's public gRPC API, forwarding
the browser's bearer token on every call (it holds none of its own)."""
