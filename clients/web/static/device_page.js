// Device: the shared queue live (WatchQueue), the device's status, and the
// controls the caller's role allows: submit the current plan, cancel a job,
// resume the queue (operator), emergency stop (admin; the API cannot tell
// an operator from an admin without acting, so operators see it too and the
// server refuses them in words).
import { get, post, showError, stream } from './api.js';
import { session } from './session.js';

const $ = (id) => document.getElementById(id);
let watching = null, statusTimer = null;

function element(tag, props = {}, ...children) {
  const e = Object.assign(document.createElement(tag), props);
  e.append(...children);
  return e;
}

async function act(route, body) {
  showError($('device-error'), null);
  try {
    await post(route, body);
    await refreshStatus();
  } catch (error) {
    showError($('device-error'), error);
  }
}

function showControls() {
  const box = $('device-controls');
  box.replaceChildren();
  const plan = session.plan();
  $('device-plan').textContent = plan ? `current plan: ${plan.label}, ${plan.steps.length} steps`
    : 'no current plan: make one on the Plan page';
  if (!session.mayOperate()) {
    box.append(element('span', { className: 'hint', textContent: session.role && session.role.role === 'preview'
      ? 'this token has the preview role: it may watch the queue, not change it' : 'enter a token to act on the device' }));
    return;
  }
  const name = element('input', { id: 'job-name', placeholder: 'job name', size: 16 });
  const submit = element('button', { id: 'submit-plan', type: 'button', textContent: 'Submit current plan', disabled: !plan });
  submit.addEventListener('click', () => {
    const current = session.plan();
    act('/api/device/submit', { steps: current.steps, planner: current.planner, name: name.value || current.label });
  });
  const resume = element('button', { id: 'resume-queue', type: 'button', textContent: 'Resume queue' });
  resume.addEventListener('click', () => act('/api/device/resume'));
  const stop = element('button', { id: 'emergency-stop', type: 'button', className: 'stop', textContent: 'EMERGENCY STOP' });
  stop.addEventListener('click', () => act('/api/device/stop', { reason: 'emergency stop from the web viewer' }));
  const file = element('input', { id: 'plan-file-for-device', type: 'file', accept: '.json',
                                  title: 'a plan.json (Plan page, hapticjam remote plan) as the current plan' });
  file.addEventListener('change', () => loadPlanFile(file.files[0]));
  box.append(name, submit, element('label', {}, 'or a plan.json ', file), resume, stop);
}

async function loadPlanFile(file) {
  showError($('device-error'), null);
  try {
    const doc = JSON.parse(await file.text());
    const steps = Array.isArray(doc) ? doc : doc.steps;
    if (!Array.isArray(steps)) throw new Error('it has no "steps" list');
    session.setPlan({ steps, planner: doc.planner || '', label: file.name });
  } catch (error) {
    showError($('device-error'), new Error(`${file.name}: not a plan.json (${error.message})`));
  }
}

function progressCell(job) {
  const bar = element('progress', { max: Math.max(1, job.steps_total), value: job.steps_done });
  return element('td', {}, bar, ` ${job.steps_done}/${job.steps_total}`);
}

function showQueue(queue) {
  const rows = queue.jobs.map((job) => {
    const active = job.state === 'queued' || job.state === 'running';
    const actions = element('td');
    if (active && session.mayOperate()) {
      const cancel = element('button', { type: 'button', className: 'cancel-job', textContent: 'cancel' });
      cancel.addEventListener('click', () => act('/api/device/cancel', { id: job.id }));
      actions.append(cancel);
    }
    const tr = element('tr', { className: job.state, id: `job-${job.id}` },
      element('td', { textContent: job.id }), element('td', { textContent: job.name }),
      element('td', { textContent: job.owner }), element('td', { textContent: job.state + (job.error ? `: ${job.error}` : '') }),
      element('td', { textContent: job.position < 0 ? '' : job.position === 0 ? 'running' : `${job.position}` }),
      progressCell(job), actions);
    return tr;
  });
  $('queue-body').replaceChildren(...rows);
  $('queue-note').textContent = (queue.paused ? `queue paused: ${queue.pause_reason}. ` : '')
    + (queue.device_connected ? '' : 'device not connected.');
  refreshStatus();
}

async function refreshStatus() {
  try {
    const s = await get('/api/device/status');
    const item = (label, value, bad) => element('span', { className: bad ? 'bad' : '' }, `${label}: ${value}`);
    $('device-status').replaceChildren(
      item('device', s.connected ? `connected (${s.endpoint})` : 'offline', !s.connected),
      item('array', `${s.rows} x ${s.cols}`),
      item('pressure', `${(s.pressure_pa / 1000).toFixed(2)} of ${(s.max_pressure_pa / 1000).toFixed(1)} kPa`),
      item('jammed', s.jammed_cells.length), item('pinned', s.pinned_nodes.length),
      ...(s.emergency_stopped ? [item('EMERGENCY STOPPED', s.pause_reason, true)] : []),
      ...(s.queue_paused && !s.emergency_stopped ? [item('queue paused', s.pause_reason, true)] : []),
      ...(s.last_error ? [item('last error', s.last_error, true)] : []));
  } catch (error) {
    showError($('device-error'), error);
  }
}

async function watch() {
  if (watching) watching.abort();
  const mine = watching = new AbortController();
  showError($('device-error'), null);
  try {
    await stream('GET', '/api/queue/watch?recent=8', undefined, (q) => showQueue(q), mine.signal);
  } catch (error) {
    if (error.name !== 'AbortError') showError($('device-error'), error);
  }
}

export const devicePage = {
  init() {
    session.onChange((what) => {
      if ($('page-device').hidden) return;
      showControls();
      if (what === 'role') watch();
    });
  },

  async enter() {
    showControls();
    watch();
    await refreshStatus();
    statusTimer = setInterval(refreshStatus, 2000);
  },

  leave() {
    if (watching) watching.abort();
    watching = null;
    clearInterval(statusTimer);
  },
};
