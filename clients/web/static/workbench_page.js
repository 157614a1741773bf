// Workbench: compare, fit or diagnose a measurement dataset (one the gateway
// was given, or a folder chosen here and uploaded), with a progress bar per
// stage, the key figures, and the report page the command makes.
import { get, showError, stream } from './api.js';

const $ = (id) => document.getElementById(id);
let running = null;

function base64(buffer) {
  let text = '';
  const bytes = new Uint8Array(buffer);
  for (let k = 0; k < bytes.length; k += 0x8000) text += String.fromCharCode(...bytes.subarray(k, k + 0x8000));
  return btoa(text);
}

// The chosen folder as an UploadedDataset: each sub-folder with a session.json
// is a session; the files under it go along by their path inside it.
async function uploadedDataset(files) {
  if (!files.length) throw new Error('choose a dataset folder (each session a sub-folder with session.json)');
  const sessions = new Map();
  let name = '';
  for (const file of files) {
    const parts = file.webkitRelativePath.split('/');
    if (parts.length < 3) continue;  // DATASET/SESSION/...
    name = parts[0];
    const session = sessions.get(parts[1]) || { name: parts[1], session_json: null, files: [] };
    sessions.set(parts[1], session);
    const path = parts.slice(2).join('/');
    if (path === 'session.json') session.session_json = await file.text();
    else session.files.push({ path, content_b64: base64(await file.arrayBuffer()) });
  }
  const complete = [...sessions.values()].filter((s) => s.session_json !== null);
  if (!complete.length) throw new Error(`folder ${name || '(chosen)'}: no sub-folder holds a session.json`);
  return { name, sessions: complete };
}

function showProgress(p) {
  const box = $('bench-progress');
  let row = [...box.children].find((r) => r.dataset.stage === p.stage);
  if (!row) {
    row = document.createElement('div');
    row.className = 'stage';
    row.dataset.stage = p.stage;
    row.append(document.createElement('progress'), document.createElement('span'));
    box.append(row);
  }
  const [bar, text] = row.children;
  bar.max = Math.max(1, p.total);
  bar.value = p.done;
  text.textContent = ` ${p.stage}: ${p.done}/${p.total}` + (p.detail ? ` ${p.detail}` : '')
    + (p.rmse_mm !== undefined ? `, RMSE ${p.rmse_mm.toFixed(3)} mm` : '');
}

function showResult(r) {
  const figures = [['RMSE', r.rmse_mm ?? r.final_rmse_mm, 'mm'], ['noise floor', r.noise_floor_mm, 'mm'],
                   ['server time', r.seconds, 's']];
  if (r.kind === 'compare') figures.push(['MAE', r.mae_mm, 'mm'], ['samples', r.samples, '']);
  if (r.kind === 'fit') {
    figures.push(['R²', r.r2, '']);
    for (const p of r.parameters.filter((q) => q.active))
      figures.push([p.name, p.value, `${p.unit} (95 %: ${p.ci95_low.toPrecision(4)} .. ${p.ci95_high.toPrecision(4)})`]);
  }
  if (r.kind === 'diagnose')
    figures.push(['verdict', r.verdict.length ? r.verdict.join(', ') : 'the baseline model suffices', ''],
                 ['baseline RMSE', r.baseline_rmse_mm, 'mm']);
  $('bench-result').replaceChildren(...figures.flatMap(([label, value, unit]) => {
    const dt = document.createElement('dt'), dd = document.createElement('dd');
    dt.textContent = label;
    dd.textContent = typeof value === 'number' ? `${Number(value.toPrecision(5))} ${unit}` : `${value} ${unit}`;
    dd.dataset.figure = label;
    return [dt, dd];
  }));
  $('bench-result').hidden = false;
  $('bench-report').srcdoc = r.report_html;
  $('bench-report').hidden = !r.report_html;
}

async function run(kind) {
  if (running) return;
  showError($('bench-error'), null);
  const options = { segments: Number($('bench-segments').value), max_iterations: Number($('bench-iterations').value),
                    effects: $('bench-effects').value.split(',').map((s) => s.trim()).filter(Boolean) };
  let body;
  try {
    body = document.querySelector('input[name=dataset-source]:checked').value === 'upload'
      ? { upload: await uploadedDataset([...$('bench-folder').files]), options }
      : { dataset: $('bench-dataset').value, options };
    if (body.dataset === '') throw new Error('the gateway was given no dataset (hapticjam-web --dataset NAME=FOLDER): upload a folder');
  } catch (error) {
    return showError($('bench-error'), error);
  }
  $('bench-progress').replaceChildren();
  $('bench-result').hidden = true;
  $('bench-report').hidden = true;
  running = new AbortController();
  $('bench-cancel').disabled = false;
  document.querySelectorAll('[data-run]').forEach((b) => { b.disabled = true; });
  try {
    await stream('POST', `/api/calibration/${kind}`, body, (e) => (e.progress ? showProgress(e.progress) : showResult(e.result)),
                 running.signal);
  } catch (error) {
    if (error.name !== 'AbortError') showError($('bench-error'), error);
  } finally {
    running = null;
    $('bench-cancel').disabled = true;
    document.querySelectorAll('[data-run]').forEach((b) => { b.disabled = false; });
  }
}

export const workbenchPage = {
  init() {
    document.querySelectorAll('[data-run]').forEach((b) => b.addEventListener('click', () => run(b.dataset.run)));
    $('bench-cancel').addEventListener('click', () => running && running.abort());
    $('bench-folder').addEventListener('change', () => {
      document.querySelector('input[name=dataset-source][value=upload]').checked = true;
    });
  },

  async enter() {
    try {
      const info = await get('/api/info');
      if ($('bench-dataset').options.length !== info.datasets.length)
        $('bench-dataset').replaceChildren(...info.datasets.map((n) => new Option(n, n)));
    } catch (error) {
      showError($('bench-error'), error);
    }
  },
};
