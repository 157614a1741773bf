// The height colour ramp of the Python client's PNGs (surface.py): blue low,
// cyan, yellow, red high. Returns [r, g, b] in 0..1.
const STOPS = [[0.0, [48, 18, 160]], [0.35, [30, 170, 220]], [0.65, [250, 220, 60]], [1.0, [200, 30, 30]]];

export function heightColour(t) {
  const u = Math.min(1, Math.max(0, Number.isFinite(t) ? t : 0));
  for (let k = 1; k < STOPS.length; k++) {
    const [t1, c1] = STOPS[k];
    if (u <= t1) {
      const [t0, c0] = STOPS[k - 1];
      const f = t1 > t0 ? (u - t0) / (t1 - t0) : 0;
      return c0.map((a, i) => (a + f * (c1[i] - a)) / 255);
    }
  }
  return STOPS[STOPS.length - 1][1].map((a) => a / 255);
}

// [lo, hi] of the finite values of some arrays, at least `minSpan` apart.
export function rangeOf(arrays, minSpan = 1) {
  let lo = Infinity, hi = -Infinity;
  for (const a of arrays) for (const v of a || []) if (Number.isFinite(v)) { lo = Math.min(lo, v); hi = Math.max(hi, v); }
  if (!Number.isFinite(lo)) return [0, minSpan];
  if (hi - lo < minSpan) hi = lo + minSpan;
  return [lo, hi];
}

export function cssColour(rgb) {
  return `rgb(${rgb.map((c) => Math.round(c * 255)).join(',')})`;
}
