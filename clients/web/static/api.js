// Calls of the gateway's /api/ routes with the session's bearer token, and
// errors turned into words a person can act on.
import { session } from './session.js';

export class ApiError extends Error {
  constructor(error, status) {
    super(`${error.call}: ${error.code}: ${error.message}` + (error.hint ? ` (${error.hint})` : ''));
    this.code = error.code;
    this.status = status;
  }
}

function headers(json) {
  const h = { 'X-Hapticjam-Web': '1' };
  if (json) h['Content-Type'] = 'application/json';
  const token = session.token();
  if (token) h['Authorization'] = 'Bearer ' + token;
  return h;
}

async function failure(response, route) {
  let doc = null;
  try { doc = await response.json(); } catch (_) { /* not JSON: a proxy or a crash */ }
  const error = doc && doc.error ? doc.error
    : { call: route, code: `HTTP ${response.status}`, message: response.statusText || 'no answer from the gateway' };
  return new ApiError(error, response.status);
}

async function send(method, route, body, signal) {
  let response;
  try {
    response = await fetch(route, { method, headers: headers(body !== undefined),
                                    body: body === undefined ? undefined : JSON.stringify(body), signal });
  } catch (e) {
    if (e.name === 'AbortError') throw e;
    throw new ApiError({ call: route, code: 'UNREACHABLE', message: 'the gateway does not answer: ' + e.message }, 0);
  }
  if (!response.ok) throw await failure(response, route);
  return response;
}

export async function get(route) {
  return (await send('GET', route)).json();
}

export async function post(route, body = {}) {
  return (await send('POST', route, body)).json();
}

// Reads a newline-delimited JSON stream, calling onEvent(object) per line;
// an {"error": ...} line ends it with an ApiError. `signal` aborts it.
export async function stream(method, route, body, onEvent, signal) {
  const response = await send(method, route, body, signal);
  const reader = response.body.getReader();
  const decoder = new TextDecoder();
  let buffered = '';
  for (;;) {
    const { value, done } = await reader.read();
    if (done) break;
    buffered += decoder.decode(value, { stream: true });
    let newline;
    while ((newline = buffered.indexOf('\n')) >= 0) {
      const line = buffered.slice(0, newline);
      buffered = buffered.slice(newline + 1);
      if (!line.trim()) continue;
      const event = JSON.parse(line);
      if (event.error) throw new ApiError(event.error, 200);
      onEvent(event);
    }
  }
}

// Shows an error (or clears it with null) in a page's message element.
export function showError(element, error) {
  element.textContent = error ? (error.message || String(error)) : '';
  element.hidden = !error;
}
