"""A Python client of hapticjam-server over its public gRPC API (proto/hapticjam/v1).

The message and stub modules are generated from proto/ at build time (CMake
target hj_python_stubs, protoc + grpc_python_plugin) into build/clients/python;
put that folder and clients/python on PYTHONPATH:

    PYTHONPATH=build/clients/python:clients/python python3 -c 'import hapticjam_client'
"""

try:
    from hapticjam.v1 import (array_pb2, device_service_pb2, device_service_pb2_grpc, goal_pb2, plan_pb2,
                              planning_service_pb2, planning_service_pb2_grpc, render_service_pb2,
                              render_service_pb2_grpc, surface_pb2)
except ImportError as e:  # pragma: no cover - a message a user can act on
    raise ImportError(
        "hapticjam_client needs the generated stubs: build them (cmake --build build --target hj_python_stubs) "
        "and put build/clients/python on PYTHONPATH (" + str(e) + ")") from e

from .client import Client, ClientError, dataset_upload, file_goal, map_goal
from .surface import Surface, write_png

__all__ = ["Client", "ClientError", "Surface", "dataset_upload", "file_goal", "map_goal", "write_png", "array_pb2",
           "device_service_pb2", "device_service_pb2_grpc", "goal_pb2", "plan_pb2", "planning_service_pb2",
           "planning_service_pb2_grpc", "render_service_pb2", "render_service_pb2_grpc", "surface_pb2"]
