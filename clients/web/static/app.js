// The single page: a tab per view (#plan, #zoom, #device, #workbench), the
// token form, and the caller's role as the server sees it.
import { get } from './api.js';
import { session } from './session.js';
import { planPage } from './plan_page.js';
import { zoomPage } from './zoom_page.js';
import { devicePage } from './device_page.js';
import { workbenchPage } from './workbench_page.js';

const pages = { plan: planPage, zoom: zoomPage, device: devicePage, workbench: workbenchPage };
let current = null;

// "#plan?map=volcano&rows=3" -> ["plan", URLSearchParams]
function route() {
  const [name, query] = location.hash.replace(/^#/, '').split('?');
  return [pages[name] ? name : 'plan', new URLSearchParams(query || '')];
}

async function show() {
  const [name, params] = route();
  document.querySelectorAll('.page').forEach((p) => { p.hidden = p.id !== 'page-' + name; });
  document.querySelectorAll('nav a').forEach((a) => a.classList.toggle('active', a.dataset.page === name));
  if (current && current !== pages[name] && current.leave) current.leave();
  current = pages[name];
  await current.enter(params);
}

async function refreshRole() {
  const badge = document.getElementById('role');
  try {
    const role = await get('/api/role');
    session.setRole(role);
    badge.textContent = !role.auth ? 'no auth: every caller may do everything'
      : role.role === 'none' ? 'no token' : role.role === 'operator' ? 'operator or admin' : role.role;
  } catch (e) {
    session.setRole(null);
    badge.textContent = e.message;
  }
}

document.getElementById('token-form').addEventListener('submit', async (e) => {
  e.preventDefault();
  const input = document.getElementById('token');
  session.setToken(input.value.trim());
  input.value = '';
  input.placeholder = session.token() ? 'token kept for this tab' : 'bearer token';
  await refreshRole();
  await show();  // the page again, with what this token may see
});

window.addEventListener('hashchange', show);
document.getElementById('token').placeholder = session.token() ? 'token kept for this tab' : 'bearer token';
Object.values(pages).forEach((p) => p.init());
refreshRole().then(show);
