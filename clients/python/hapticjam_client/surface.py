"""Heights from the API as rows of floats, and a PNG writer in the standard
library only (zlib + struct): a height map as a colour picture."""

import math
import struct
import zlib


class Surface:
    """Heights in mm on a grid: rows[i][j], row i along +y (the API's order)."""

    def __init__(self, rows, cols, heights):
        if rows * cols != len(heights):
            raise ValueError(f"{len(heights)} heights for {rows} x {cols} points")
        self.rows, self.cols = rows, cols
        self.values = [list(heights[i * cols:(i + 1) * cols]) for i in range(rows)]

    @classmethod
    def from_snapshot(cls, snapshot):
        return cls(snapshot.point_rows, snapshot.point_cols, snapshot.heights_mm)

    @classmethod
    def from_frame(cls, frame):
        return cls(frame.grid.ny, frame.grid.nx, frame.heights_mm)

    def finite(self):
        return [v for row in self.values for v in row if math.isfinite(v)]


def _colour(t):
    """A blue -> cyan -> yellow -> red ramp for t in [0, 1]."""
    stops = [(0.0, (48, 18, 160)), (0.35, (30, 170, 220)), (0.65, (250, 220, 60)), (1.0, (200, 30, 30))]
    for (t0, c0), (t1, c1) in zip(stops, stops[1:]):
        if t <= t1:
            f = (t - t0) / (t1 - t0) if t1 > t0 else 0.0
            return tuple(int(round(a + f * (b - a))) for a, b in zip(c0, c1))
    return stops[-1][1]


def write_png(path, surface, scale=8):
    """Writes the surface as an RGB PNG, each point a scale x scale block, the
    lowest height blue and the highest red, +y up (row 0 at the bottom), NaN grey."""
    finite = surface.finite()
    lo, hi = (min(finite), max(finite)) if finite else (0.0, 1.0)
    span = hi - lo if hi > lo else 1.0
    width, height = surface.cols * scale, surface.rows * scale
    raw = bytearray()
    for i in reversed(range(surface.rows)):
        line = bytearray()
        for v in surface.values[i]:
            rgb = _colour((v - lo) / span) if math.isfinite(v) else (128, 128, 128)
            line += bytes(rgb) * scale
        for _ in range(scale):
            raw += b"\x00" + line  # filter type 0 per scanline

    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)

    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(bytes(raw), 9)) + chunk(b"IEND", b"")
    with open(path, "wb") as f:
        f.write(png)
    return lo, hi
