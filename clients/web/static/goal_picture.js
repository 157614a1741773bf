// A goal map seen flat: its heights read in the browser (a DEM table in CSV,
// or a PNG / JPEG picture's grey level), turned north-up by its sidecar's
// "orientation" as the server's importer does (src/shapes/sidecar.h), and
// drawn coloured by height. Regions are fractions of this north-up picture,
// x along columns, y along rows from the top (proto/hapticjam/v1/goal.proto).
import { get } from './api.js';
import { heightColour, rangeOf } from './colours.js';

// {width, height, values: Float64Array (height x width, row 0 at the top)}.
export function parseCsv(text, name) {
  const rows = text.split(/\r?\n/).filter((l) => l.trim()).map((l) => l.split(',').map((v) => Number(v.trim())));
  const width = rows.length ? rows[0].length : 0;
  if (!width) throw new Error(`${name}: no numbers`);
  rows.forEach((r, i) => { if (r.length !== width) throw new Error(`${name}: line ${i + 1} has ${r.length} values, line 1 has ${width}`); });
  return { width, height: rows.length, values: Float64Array.from(rows.flat()) };
}

async function parseImage(blob, name) {
  let bitmap;
  try { bitmap = await createImageBitmap(blob); } catch (e) { throw new Error(`${name}: the browser cannot read this picture`); }
  const c = document.createElement('canvas');
  c.width = bitmap.width;
  c.height = bitmap.height;
  const g = c.getContext('2d');
  g.drawImage(bitmap, 0, 0);
  const rgba = g.getImageData(0, 0, c.width, c.height).data;
  const values = new Float64Array(c.width * c.height);
  for (let k = 0; k < values.length; k++) values[k] = 0.299 * rgba[4 * k] + 0.587 * rgba[4 * k + 1] + 0.114 * rgba[4 * k + 2];
  return { width: c.width, height: c.height, values };
}

// The sidecar's numpy expression ("a[::-1, ::-1]", ".T", ...) applied to the picture.
export function reorient(picture, expression) {
  let text = expression.replace(/[(#].*$/, '').replace(/\s+/g, '');
  if (!text.startsWith('a')) throw new Error(`orientation "${expression}": expected an expression of a`);
  text = text.slice(1);
  let p = picture;
  const flip = (rows, cols) => {
    const out = new Float64Array(p.values.length);
    for (let i = 0; i < p.height; i++)
      for (let j = 0; j < p.width; j++)
        out[i * p.width + j] = p.values[(rows ? p.height - 1 - i : i) * p.width + (cols ? p.width - 1 - j : j)];
    p = { width: p.width, height: p.height, values: out };
  };
  const slices = { '[::-1]': [true, false], '[::-1,:]': [true, false], '[:,::-1]': [false, true],
                   '[::-1,::-1]': [true, true], '[:,:]': [false, false] };
  while (text) {
    if (text.startsWith('.T')) {
      const out = new Float64Array(p.values.length);
      for (let i = 0; i < p.height; i++) for (let j = 0; j < p.width; j++) out[j * p.height + i] = p.values[i * p.width + j];
      p = { width: p.height, height: p.width, values: out };
      text = text.slice(2);
      continue;
    }
    const slice = Object.keys(slices).sort((a, b) => b.length - a.length).find((s) => text.startsWith(s));
    if (!slice) throw new Error(`orientation "${expression}": cannot read "${text}"`);
    flip(...slices[slice]);
    text = text.slice(slice.length);
  }
  return p;
}

export async function pictureFromBlob(blob, name, sidecarText) {
  const extension = name.toLowerCase().split('.').pop();
  let picture;
  if (extension === 'csv') picture = parseCsv(await blob.text(), name);
  else if (['png', 'jpg', 'jpeg'].includes(extension)) picture = await parseImage(blob, name);
  else return null;  // meshes and TIFFs: the server reads them, the page does not draw them
  if (sidecarText) {
    let sidecar;
    try { sidecar = JSON.parse(sidecarText); } catch (e) { throw new Error(`${name}: its sidecar is not JSON (${e.message})`); }
    const expression = sidecar.orientation && sidecar.orientation.north_up_numpy;
    if (typeof expression === 'string') picture = reorient(picture, expression);
  }
  return picture;
}

// A server map's picture, from the file the gateway was given (null if none).
export async function mapPicture(name) {
  const info = await get('/api/info');
  const fileName = info.map_files[name];
  if (!fileName) return null;
  const headers = { 'X-Hapticjam-Web': '1' };
  const file = await fetch(`/api/maps/${encodeURIComponent(name)}/file`, { headers });
  if (!file.ok) throw new Error(`map ${name}: the gateway could not send its file (HTTP ${file.status})`);
  const sidecar = await (await fetch(`/api/maps/${encodeURIComponent(name)}/sidecar`, { headers })).text();
  return pictureFromBlob(await file.blob(), fileName, sidecar.trim() === '{}' ? '' : sidecar);
}

// Draws the picture to fit the canvas, keeping its aspect; returns the
// drawn box {x, y, w, h} in canvas pixels (for mapping a drag to fractions).
export function drawPicture(canvas, picture) {
  const w = canvas.width = canvas.clientWidth || 600, h = canvas.height = canvas.clientHeight || 400;
  const g = canvas.getContext('2d');
  g.fillStyle = '#f4f4f0';
  g.fillRect(0, 0, w, h);
  if (!picture) return { x: 0, y: 0, w, h };
  const scale = Math.min(w / picture.width, h / picture.height);
  const box = { w: picture.width * scale, h: picture.height * scale };
  box.x = (w - box.w) / 2;
  box.y = (h - box.h) / 2;
  const [lo, hi] = rangeOf([picture.values], 1e-9);
  const image = g.createImageData(picture.width, picture.height);
  for (let k = 0; k < picture.values.length; k++) {
    const v = picture.values[k];
    const rgb = Number.isFinite(v) ? heightColour((v - lo) / (hi - lo)) : [0.5, 0.5, 0.5];
    image.data.set([...rgb.map((c) => Math.round(c * 255)), 255], 4 * k);
  }
  const full = document.createElement('canvas');
  full.width = picture.width;
  full.height = picture.height;
  full.getContext('2d').putImageData(image, 0, 0);
  g.imageSmoothingEnabled = false;
  g.drawImage(full, box.x, box.y, box.w, box.h);
  return box;
}

