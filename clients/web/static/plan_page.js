// Plan: a goal (server map or uploaded file) on an array, streamed: progress,
// each surface snapshot in 3-D, then the result's figures and plan.json.
import { ApiError, get, showError, stream } from './api.js';
import { session } from './session.js';
import { createSurfaceView } from './surface_view.js';
import { drawPicture, mapPicture, pictureFromBlob } from './goal_picture.js';
import { rangeOf } from './colours.js';
import { DEFAULT_CELL_MM } from './surface_grid.js';

const $ = (id) => document.getElementById(id);
let view = null, running = null, snapshots = [], result = null, request = null;

function fileAsBase64(file) {
  return new Promise((resolve, reject) => {
    const reader = new FileReader();
    reader.onload = () => resolve(reader.result.slice(reader.result.indexOf(',') + 1));
    reader.onerror = () => reject(new Error(`cannot read ${file.name}`));
    reader.readAsDataURL(file);
  });
}

function numberField(id, name) {
  const v = Number($(id).value);
  if (!Number.isInteger(v)) throw new Error(`${name} must be a whole number, got "${$(id).value}"`);
  return v;
}

function regionField() {
  const v = $('plan-region').value.trim().split(/[\s,]+/).map(Number);
  if (v.length !== 4 || v.some((x) => !Number.isFinite(x))) throw new Error('region needs four numbers: x0 y0 x1 y1 (fractions)');
  return v;
}

async function goalFromForm() {
  const region = regionField();
  const whole = region[0] === 0 && region[1] === 0 && region[2] === 1 && region[3] === 1;
  const goal = whole ? {} : { region };
  if (document.querySelector('input[name=source]:checked').value === 'map') {
    if (!$('plan-map').value) throw new Error('the server holds no map: choose a file instead');
    return { ...goal, map: $('plan-map').value };
  }
  const file = $('plan-file').files[0];
  if (!file) throw new Error('choose a goal file (image, DEM table or mesh)');
  const sidecar = $('plan-sidecar').files[0];
  return { ...goal, file: { name: file.name, content_b64: await fileAsBase64(file),
                            sidecar_json: sidecar ? await sidecar.text() : '' } };
}

async function showGoalPicture(goal) {
  const canvas = $('plan-goal-picture');
  try {
    let picture = null;
    if (goal.map) picture = await mapPicture(goal.map);
    else {
      const sidecar = $('plan-sidecar').files[0];
      picture = await pictureFromBlob($('plan-file').files[0], goal.file.name, sidecar ? await sidecar.text() : '');
    }
    drawPicture(canvas, picture);
    canvas.parentElement.hidden = !picture;
  } catch (e) {
    canvas.parentElement.hidden = true;
  }
}

// The replayed snapshots share one colour scale (all of them and the goal);
// the final surface and its goal share theirs.
function picture(snapshot, withGoal) {
  const goalHeights = withGoal && result ? result.goal_heights_mm : null;
  const all = goalHeights ? [snapshot.heights_mm, goalHeights]
    : snapshots.map((s) => s.heights_mm).concat(result ? [result.goal_heights_mm] : []);
  return { snapshot, goalHeights, rows: request.rows, cols: request.cols, range: rangeOf(all) };
}

function onEvent(event) {
  if (event.progress) {
    $('plan-progress').value = event.progress.fraction;
    $('plan-message').textContent = event.progress.message;
  } else if (event.snapshot) {
    snapshots.push(event.snapshot);
    $('plan-snapshots').textContent = String(snapshots.length);
    view.show(picture(event.snapshot, false));
  } else if (event.result) {
    result = event.result;
    showResult();
  }
}

function showResult() {
  $('plan-progress').value = 1;
  const c = result.correlation;
  $('plan-correlation').textContent = c === null ? `undefined (${result.correlation_undefined})` : c.toFixed(4);
  $('plan-correlation').dataset.value = c === null ? '' : String(c);
  $('plan-laplace').textContent = result.laplace_mean.toFixed(4);
  $('plan-steps').textContent = `${result.steps.length} (${result.planner || 'planner'})`;
  $('plan-seconds').textContent = `${result.seconds.toFixed(2)} s` + (result.cached ? ', from the cache' : '');
  $('plan-result').hidden = false;
  const segments = (result.predicted.point_rows - 1) / request.rows;
  const doc = { format: 'hapticjam.plan/1', goal: request.goal.map ? 'map:' + request.goal.map : request.goal.file.name,
                array: { rows: request.rows, cols: request.cols, cell_size_mm: DEFAULT_CELL_MM, segments },
                planner: result.planner, steps: result.steps, correlation: c, laplace_mean: result.laplace_mean,
                snapshots: snapshots.length, cached: result.cached };
  if (request.goal.region) doc.region = request.goal.region;
  const link = $('plan-download');
  if (link.href.startsWith('blob:')) URL.revokeObjectURL(link.href);
  link.href = URL.createObjectURL(new Blob([JSON.stringify(doc, null, 1) + '\n'], { type: 'application/json' }));
  $('plan-actions').hidden = false;
  session.setPlan({ steps: result.steps, planner: result.planner, label: `${doc.goal} on ${request.rows} x ${request.cols}` });
  // The final surface with the goal beside it; the slider replays the snapshots.
  snapshots.push(result.predicted);
  $('plan-scrub').max = String(snapshots.length);
  $('plan-scrub').value = String(snapshots.length);
  $('plan-scrub-at').textContent = 'final';
  $('plan-scrub-label').hidden = false;
  view.show(picture(result.predicted, true));
}

async function start(e) {
  if (e) e.preventDefault();
  if (running) return;
  showError($('plan-error'), null);
  try {
    request = { rows: numberField('plan-rows', 'rows'), cols: numberField('plan-cols', 'cols'),
                segments: numberField('plan-segments', 'segments'), planner: $('plan-planner').value,
                goal: await goalFromForm() };
  } catch (error) {
    return showError($('plan-error'), error);
  }
  snapshots = [];
  result = null;
  ['plan-result', 'plan-actions', 'plan-scrub-label'].forEach((id) => { $(id).hidden = true; });
  $('plan-snapshots').textContent = '0';
  $('plan-progress').value = 0;
  $('plan-message').textContent = 'waiting for a worker';
  showGoalPicture(request.goal);
  running = new AbortController();
  $('plan-start').disabled = true;
  $('plan-cancel').disabled = false;
  try {
    await stream('POST', '/api/plan', request, onEvent, running.signal);
    if (!result) throw new Error('the plan stream ended without a result');
    $('plan-message').textContent = 'done';
  } catch (error) {
    $('plan-message').textContent = error.name === 'AbortError' ? 'cancelled' : 'failed';
    if (error.name !== 'AbortError') showError($('plan-error'), error);
  } finally {
    running = null;
    $('plan-start').disabled = false;
    $('plan-cancel').disabled = true;
  }
}

function scrub() {
  const k = Number($('plan-scrub').value);
  const last = k === snapshots.length && result;
  $('plan-scrub-at').textContent = last ? 'final' : `${k} of ${snapshots.length - (result ? 1 : 0)}`;
  view.show(picture(snapshots[k - 1], last));
}

function fill(select, names, empty) {
  const before = select.value;
  select.replaceChildren(...names.map((n) => new Option(n, n)));
  if (!names.length && empty) select.append(new Option(empty, ''));
  if (names.includes(before)) select.value = before;
}

export const planPage = {
  init() {
    $('plan-form').addEventListener('submit', start);
    $('plan-cancel').addEventListener('click', () => running && running.abort());
    $('plan-scrub').addEventListener('input', scrub);
    $('plan-planner').addEventListener('change', () => { $('plan-planner').dataset.chosen = '1'; });
    $('plan-file').addEventListener('change', () => { document.querySelector('input[name=source][value=file]').checked = true; });
  },

  // URL parameters fill the form (map, rows, cols, segments, planner, region); auto=1 starts the plan.
  async enter(params) {
    // Until the server's maps and planners are in the form, a plan would be
    // started from an empty map list ("the server holds no map").
    if (!running) $('plan-start').disabled = true;
    if (!view) view = await createSurfaceView($('plan-view'));
    $('plan-view').dataset.kind = view.kind;
    try {
      const info = await get('/api/info');
      fill($('plan-map'), info.maps, '(no maps)');
      fill($('plan-planner'), info.planners);
      $('plan-planner').prepend(new Option("server's default", ''));
      if (!params.has('planner') && !$('plan-planner').dataset.chosen) $('plan-planner').value = '';
      $('plan-file').accept = info.goal_extensions.join(',');
    } catch (error) {
      showError($('plan-error'), error instanceof ApiError ? error : new Error(String(error)));
    } finally {
      if (!running) $('plan-start').disabled = false;
    }
    for (const [key, id] of [['map', 'plan-map'], ['rows', 'plan-rows'], ['cols', 'plan-cols'],
                             ['segments', 'plan-segments'], ['planner', 'plan-planner'], ['region', 'plan-region']])
      if (params.has(key)) $(id).value = params.get(key);
    if (params.has('map')) document.querySelector('input[name=source][value=map]').checked = true;
    if (params.get('auto') === '1' && !result && !running) start();
  },
};
