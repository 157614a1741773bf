"""gRPC status codes as HTTP statuses, and the JSON error body the pages
show in words: {"error": {"call", "code", "message"}}."""

import grpc

HTTP_STATUS = {
    grpc.StatusCode.INVALID_ARGUMENT: 400, grpc.StatusCode.OUT_OF_RANGE: 400,
    grpc.StatusCode.UNAUTHENTICATED: 401, grpc.StatusCode.PERMISSION_DENIED: 403,
    grpc.StatusCode.NOT_FOUND: 404, grpc.StatusCode.FAILED_PRECONDITION: 409, grpc.StatusCode.ALREADY_EXISTS: 409,
    grpc.StatusCode.ABORTED: 409, grpc.StatusCode.RESOURCE_EXHAUSTED: 429, grpc.StatusCode.CANCELLED: 499,
    grpc.StatusCode.UNAVAILABLE: 503, grpc.StatusCode.DEADLINE_EXCEEDED: 504,
}

# What a person can do about a code, added to the server's own message.
HINTS = {
    grpc.StatusCode.UNAUTHENTICATED: "enter a valid token at the top of the page",
    grpc.StatusCode.PERMISSION_DENIED: "this token's role does not allow it",
    grpc.StatusCode.UNAVAILABLE: "the gateway cannot reach hapticjam-server; is it running?",
    grpc.StatusCode.RESOURCE_EXHAUSTED: "the server is busy; try again in a moment",
}


def error_body(call, code, message):
    """code: a grpc.StatusCode or a plain name ("BAD_REQUEST")."""
    name = code.name if isinstance(code, grpc.StatusCode) else code
    hint = HINTS.get(code) if isinstance(code, grpc.StatusCode) else None
    return {"error": {"call": call, "code": name, "message": message, "hint": hint}}


def http_status(code):
    return HTTP_STATUS.get(code, 500)
