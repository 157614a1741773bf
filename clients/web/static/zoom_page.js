// Zoom: a map drawn flat; a dragged rectangle becomes a Preview of that
// region; each region answered is kept, so going back to one is instant
// (from this page's memory; the server's cache answers a repeat too).
import { get, post, showError } from './api.js';
import { createSurfaceView } from './surface_view.js';
import { drawPicture, mapPicture } from './goal_picture.js';

const $ = (id) => document.getElementById(id);
let view = null, picture = null, box = null, drag = null;
const answers = new Map();  // key -> {region, response}
const history = [];         // keys in the order first asked

const round = (v) => Math.round(v * 1000) / 1000;

function key(map, rows, cols, region) {
  return JSON.stringify([map, rows, cols, region]);
}

function redraw(rectangle) {
  const canvas = $('zoom-canvas');
  box = drawPicture(canvas, picture);
  const g = canvas.getContext('2d');
  if (!picture) {
    g.strokeStyle = '#999';
    g.strokeRect(box.x + 0.5, box.y + 0.5, box.w - 1, box.h - 1);
  }
  if (rectangle) {
    const [x0, y0, x1, y1] = rectangle;
    g.strokeStyle = '#000';
    g.lineWidth = 2;
    g.strokeRect(box.x + x0 * box.w, box.y + y0 * box.h, (x1 - x0) * box.w, (y1 - y0) * box.h);
  }
}

// A mouse position as fractions of the drawn map, clamped to [0, 1].
function fractionAt(event) {
  const r = $('zoom-canvas').getBoundingClientRect();
  const clamp = (v) => Math.min(1, Math.max(0, v));
  return [clamp((event.clientX - r.left - box.x) / box.w), clamp((event.clientY - r.top - box.y) / box.h)];
}

function showAnswer(entry, fromPage) {
  const r = entry.response;
  view.show({ snapshot: r.predicted, goalHeights: r.goal_heights_mm, rows: entry.rows, cols: entry.cols });
  $('zoom-region').textContent = entry.region.join(', ');
  $('zoom-correlation').textContent = r.correlation === null ? `undefined (${r.correlation_undefined})` : r.correlation.toFixed(4);
  $('zoom-source').textContent = fromPage ? 'instant, from this page (asked before)'
    : r.cached ? `from the server's cache (${r.seconds.toFixed(3)} s)` : `planned on the server in ${r.seconds.toFixed(2)} s`;
  $('zoom-result').hidden = false;
  redraw(entry.region);
}

function showHistory() {
  $('zoom-history').replaceChildren(...history.map((k, n) => {
    const b = document.createElement('button');
    b.type = 'button';
    b.textContent = `${n + 1}: ${answers.get(k).region.join(' ')}`;
    b.addEventListener('click', () => showAnswer(answers.get(k), true));
    return b;
  }));
}

export async function previewRegion(region) {
  const map = $('zoom-map').value, rows = Number($('zoom-rows').value), cols = Number($('zoom-cols').value);
  const k = key(map, rows, cols, region);
  showError($('zoom-error'), null);
  if (answers.has(k)) return showAnswer(answers.get(k), true);
  $('zoom-source').textContent = 'asking the server...';
  redraw(region);
  try {
    const response = await post('/api/preview', { rows, cols, goal: { map, region } });
    answers.set(k, { region, rows, cols, response });
    history.push(k);
    showHistory();
    showAnswer(answers.get(k), false);
  } catch (error) {
    showError($('zoom-error'), error);
  }
}

async function loadMap() {
  const map = $('zoom-map').value;
  picture = null;
  $('zoom-caption').textContent = '';
  try {
    picture = map ? await mapPicture(map) : null;
    $('zoom-caption').textContent = picture ? `map ${map}, north up`
      : `map ${map}: the gateway has no file to draw it (hapticjam-web --map ${map}=FILE); drag on the outline`;
  } catch (error) {
    showError($('zoom-error'), error);
  }
  redraw(null);
}

export const zoomPage = {
  init() {
    const canvas = $('zoom-canvas');
    canvas.addEventListener('mousedown', (e) => { drag = fractionAt(e); });
    canvas.addEventListener('mousemove', (e) => {
      if (!drag) return;
      const [x, y] = fractionAt(e);
      redraw([Math.min(drag[0], x), Math.min(drag[1], y), Math.max(drag[0], x), Math.max(drag[1], y)]);
    });
    window.addEventListener('mouseup', (e) => {
      if (!drag) return;
      const [x, y] = fractionAt(e);
      const region = [Math.min(drag[0], x), Math.min(drag[1], y), Math.max(drag[0], x), Math.max(drag[1], y)].map(round);
      drag = null;
      if (region[2] - region[0] < 0.02 || region[3] - region[1] < 0.02) return redraw(null);  // a click, not a drag
      previewRegion(region);
    });
    $('zoom-map').addEventListener('change', loadMap);
  },

  async enter() {
    if (!view) view = await createSurfaceView($('zoom-view'));
    try {
      const info = await get('/api/info');
      if ($('zoom-map').options.length !== info.maps.length) {
        $('zoom-map').replaceChildren(...info.maps.map((n) => new Option(n, n)));
        await loadMap();
      }
      if (!info.maps.length) showError($('zoom-error'), new Error('the server holds no map (hapticjam-server --map NAME=FILE)'));
    } catch (error) {
      showError($('zoom-error'), error);
    }
  },
};
