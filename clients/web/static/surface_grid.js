// Where a snapshot's mesh points, cells and nodes are. A snapshot has
// point_rows x point_cols points (R p + 1 by C p + 1), row i along +y; cell
// [row, col] spans points row p .. (row + 1) p, col p .. (col + 1) p; node
// [a, b] is point (a p, b p). In-plane positions are x_mm / y_mm when the
// server sent them, else the rest grid of cell_mm / p spacing.
export const DEFAULT_CELL_MM = 38;

export function gridOf(snapshot, rows, cols, cellMm = DEFAULT_CELL_MM) {
  const ny = snapshot.point_rows, nx = snapshot.point_cols;
  const p = Math.max(1, Math.round((nx - 1) / cols));
  const spacing = cellMm / p;
  const moved = snapshot.x_mm && snapshot.x_mm.length === nx * ny;
  return {
    nx, ny, p, rows, cols,
    widthMm: (nx - 1) * spacing, depthMm: (ny - 1) * spacing,
    x: (k) => (moved ? snapshot.x_mm[k] : (k % nx) * spacing),
    y: (k) => (moved ? snapshot.y_mm[k] : Math.floor(k / nx) * spacing),
    restX: (k) => (k % nx) * spacing,
    restY: (k) => Math.floor(k / nx) * spacing,
    index: (i, j) => i * nx + j,
  };
}

// Point indices around cell [row, col], in order (a closed loop).
export function cellOutline(grid, row, col) {
  const { p } = grid;
  const i0 = row * p, j0 = col * p, out = [];
  for (let j = j0; j <= j0 + p; j++) out.push(grid.index(i0, j));
  for (let i = i0 + 1; i <= i0 + p; i++) out.push(grid.index(i, j0 + p));
  for (let j = j0 + p - 1; j >= j0; j--) out.push(grid.index(i0 + p, j));
  for (let i = i0 + p - 1; i > i0; i--) out.push(grid.index(i, j0));
  return out;
}

export function nodePoint(grid, a, b) {
  return grid.index(a * grid.p, b * grid.p);
}
