// What the browser keeps for this tab: the bearer token (sessionStorage, so
// it is entered once per tab and gone when the tab closes), the caller's role
// as the server sees it, and the plan last made on the Plan page.
const TOKEN_KEY = 'hapticjam.token';
const PLAN_KEY = 'hapticjam.plan';
const listeners = [];

export const session = {
  role: null,  // {role: "preview" | "operator" | "admin" | "none", auth: bool}

  token() { return sessionStorage.getItem(TOKEN_KEY) || ''; },

  setToken(token) {
    if (token) sessionStorage.setItem(TOKEN_KEY, token);
    else sessionStorage.removeItem(TOKEN_KEY);
  },

  // At least operator (the role SubmitJob, CancelJob and ResumeQueue need).
  mayOperate() { return !!this.role && (this.role.role === 'operator' || this.role.role === 'admin'); },

  plan() {
    const text = sessionStorage.getItem(PLAN_KEY);
    return text ? JSON.parse(text) : null;
  },

  setPlan(doc) {
    sessionStorage.setItem(PLAN_KEY, JSON.stringify(doc));
    listeners.forEach((f) => f('plan'));
  },

  setRole(role) {
    this.role = role;
    listeners.forEach((f) => f('role'));
  },

  onChange(f) { listeners.push(f); },
};
