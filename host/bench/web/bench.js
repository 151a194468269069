// The bench page: it draws what the server computed (SI values, the link budget, the running fit)
// and sends the user's requests. The only processing here is for display: min/max per pixel
// column of the scope's window (the data on disk are never decimated).
'use strict';

const bench = {
  board: null,          // GET /api/board
  state: null,          // the last `state` event
  fit: null,            // the last `fit` event
  names: [],            // the columns of the running acquisition (t_s first)
  buffers: {},          // column name -> ring buffer
  time: null,           // ring buffer of t_s
  frames: 0,            // animation frames drawn (for the frame-rate benchmark)
  blocks: 0,            // blocks received
  lastDhat: null,       // the newest d_hat_n (or d_hat_q31) value
  paused: false,
  dirty: false,
  plots: [],
};
window.bench = bench;

const kMaxBufferS = 10;  // the longest time base

class Ring {
  constructor(n) { this.a = new Float64Array(n); this.n = 0; this.head = 0; }
  push(v) { this.a[this.head] = v; this.head = (this.head + 1) % this.a.length; if (this.n < this.a.length) this.n++; }
  // i-th oldest value
  at(i) { return this.a[(this.head - this.n + i + this.a.length) % this.a.length]; }
}

async function api(path, body) {
  const init = body === undefined ? {headers: access.headers()} : {
    method: 'POST', headers: access.headers({'Content-Type': 'application/json'}), body: JSON.stringify(body)};
  const r = await fetch(path, init);
  const j = await r.json().catch(() => ({error: 'HTTP ' + r.status}));
  if (!r.ok) throw new Error(j.error || ('HTTP ' + r.status));
  return j;
}

function rows(table, pairs) {
  table.replaceChildren(...pairs.map(([k, v]) => {
    const tr = document.createElement('tr');
    const a = document.createElement('td'); a.textContent = k;
    const b = document.createElement('td'); b.textContent = v;
    tr.append(a, b); return tr;
  }));
}

function say(text, error) {
  const m = document.getElementById('message');
  m.textContent = text; m.className = error ? 'error' : 'muted';
}

const fmt = (v, d = 4) => (v === null || v === undefined) ? '—' : Number(v).toPrecision(d);

// ---- board view --------------------------------------------------------------------------------

function unitOf(column) {
  if (column.startsWith('d_hat_n')) return 'N';
  if (column === 'd_hat_q31') return 'Q31';
  const ch = (bench.board?.channels || []).find(c => c.column === column);
  return ch ? ch.unit : '';
}

async function loadBoard() {
  const b = await api('/api/board');
  bench.board = b;
  const id = b.identity;
  rows(document.getElementById('identity'), [
    ['device', id.device], ['firmware', id.firmware + ' (build ' + id.build_id + ')'],
    ['protocol', id.protocol], ['converter', id.adc_bits + ' bit'],
    ['log', (id.log_capacity_bytes / 1024).toFixed(0) + ' KiB'],
    ['link', id.link_reports_per_s + ' reports/s'],
    // The board's own state in the device library's words (a finished acquisition is stopped).
    ['status', !b.status ? 'acquiring (this bench)' : b.status.text]]);
  document.getElementById('identity').dataset.sampling = b.status ? String(b.status.sampling) : 'bench';
  const c = b.calibration;
  const cal = [['state', c.state + (c.slot !== 255 ? ' (slot ' + c.slot + ')' : '')]];
  if (c.label !== undefined) {
    cal.push(['label', c.label], ['created', new Date(c.created_unix_s * 1000).toISOString()],
             ['masses', c.masses_kg.map(m => fmt(m)).join(', ') + ' kg'],
             ['observer', c.has_observer ? 'yes' : 'no']);
  }
  cal.push(['units', b.channels.map(ch => ch.name + ' ' + ch.unit).join(', ')]);
  rows(document.getElementById('calibration'), cal);
  document.querySelectorAll('.emu').forEach(e => { e.style.display = id.emulator ? '' : 'none'; });
  const box = document.getElementById('channels');
  if (!box.children.length) {
    for (const ch of b.channels) {
      const l = document.createElement('label');
      const i = document.createElement('input');
      i.type = 'checkbox'; i.value = ch.name; i.checked = ['force1', 'force2', 'acc1', 'acc2'].includes(ch.name);
      i.addEventListener('change', updateBudget);
      l.append(i, ' ' + ch.name); box.append(l);
    }
    const rate = document.getElementById('rate');
    for (const hz of [10000, 5000, 2500, 2000, 1000, 500]) {
      const period = Math.round(1e6 / hz);
      if (period < id.min_sample_period_us) continue;
      const o = document.createElement('option'); o.value = period; o.textContent = hz + ' Hz';
      if (hz === 5000) o.selected = true;
      rate.append(o);
    }
    logRates();
    document.getElementById('log-dob').checked = c.has_observer;
    document.getElementById('log-dob').disabled = !c.has_observer;
  }
}

// The log rates of the sample rate chosen: "auto" (the server takes the highest whose log holds
// the acquisition: device::DecimationThatFits), every sample, and decimations the board has.
function logRates() {
  const sel = document.getElementById('log-rate');
  const keep = sel.value || 'auto';
  const hz = 1e6 / Number(document.getElementById('rate').value);
  const options = [['auto', 'auto (what the link carries)'], [String(hz), 'every sample']];
  for (const d of [2, 4, 5, 10, 20, 25, 50, 100]) options.push([String(hz / d), (hz / d) + ' Hz']);
  sel.replaceChildren(...options.map(([v, t]) => {
    const o = document.createElement('option'); o.value = v; o.textContent = t; return o;
  }));
  sel.value = options.some(([v]) => v === keep) ? keep : 'auto';
}

// What an empty Parameters field does: the scenario's own defaults.
function scenarioHint() {
  const sc = document.getElementById('scenario');
  const p = document.getElementById('scenario-params');
  p.placeholder = sc.selectedOptions[0]?.dataset.empty || '';
  p.disabled = !sc.value;
}

function ask() {
  const lr = document.getElementById('log-rate').value;
  const a = {
    sample_period_us: Number(document.getElementById('rate').value),
    channels: [...document.querySelectorAll('#channels input:checked')].map(i => i.value),
    seconds: Number(document.getElementById('seconds').value),
    log_rate_hz: lr === 'auto' ? 'auto' : Number(lr),
    log_dob: document.getElementById('log-dob').checked,
  };
  const sc = document.getElementById('scenario').value;
  if (sc && bench.board?.identity.emulator) {
    a.scenario = sc;
    const params = document.getElementById('scenario-params').value.trim();
    // Sent as typed: the server reads and checks them.
    if (params) a.scenario_params = params.split(/[\s,]+/).map(Number);
  }
  const fit = document.getElementById('fit-measured').value;
  if (fit) a.fit_measured = fit;
  const lp = document.getElementById('fit-lowpass').value.trim();
  if (fit && lp) a.fit_lowpass_hz = Number(lp);  // the server checks it
  return a;
}

// The budget box: the device library's lines (device::DescribeBudget) and its refusal, in the
// page's words.
async function updateBudget() {
  const refusal = document.getElementById('budget-refusal');
  const table = document.getElementById('budget');
  try {
    const b = await api('/api/budget', ask());
    rows(table, b.lines);
    refusal.textContent = b.refusal || '';
    table.dataset.fits = b.refusal ? 'no' : 'yes';
    table.dataset.logRateHz = b.log_rate_hz;
  } catch (e) { refusal.textContent = e.message; table.dataset.fits = 'no'; }
}

// ---- live channel ------------------------------------------------------------------------------

// The form shows the running acquisition's settings (after a reload: the one the server runs).
function showAsk(a) {
  const set = (id, v) => { document.getElementById(id).value = v; };
  set('rate', a.sample_period_us);
  logRates();
  set('log-rate', a.log_rate_hz === undefined ? String(1e6 / a.sample_period_us) : String(a.log_rate_hz));
  document.querySelectorAll('#channels input').forEach(i => { i.checked = a.channels.includes(i.value); });
  document.getElementById('log-dob').checked = !!a.log_dob;
  set('seconds', a.seconds);
  set('scenario', a.scenario || '');
  scenarioHint();
  set('scenario-params', (a.scenario_params || []).join(', '));
  set('fit-measured', a.fit_measured || '');
  set('fit-lowpass', a.fit_lowpass_hz === undefined ? '' : a.fit_lowpass_hz);
  document.getElementById('acq-form').dataset.shows = JSON.stringify(a);
  updateBudget();
}

function onState(s) {
  const prev = bench.state;
  bench.state = s;
  if (s.running && s.ask && (!prev || prev.name !== s.name)) showAsk(s.ask);
  const line = s.running && s.view === 'watch' ? 'watching ' + s.name + ' (the Watch view)'
    : s.running ? 'acquiring ' + s.name + ': ' + s.records + ' records'
    : s.view === 'watch' ? 'last: ' + s.name + ' (the Watch view): ' + s.blocks + ' blocks in ' + s.journal + (s.error ? ' — ' + s.error : '')
    : s.name ? 'last: ' + s.records + ' records' + (s.file ? ' in ' + s.file : '') + (s.error ? ' — ' + s.error : '')
    : 'idle';
  document.getElementById('acq-state').textContent = line;
  document.body.dataset.running = s.running ? 'yes' : 'no';
  if (s.error && !(prev && prev.error === s.error)) say(s.name + ': ' + s.error, true);
  if (s.running && (!prev || prev.name !== s.name)) resetScope();
  if (prev && prev.running && !s.running) loadBoard().catch(() => {});
}

function resetScope() {
  bench.names = []; bench.buffers = {}; bench.time = null; bench.dirty = true;
  bench.lastDhat = null;
  const scope = document.getElementById('scope');
  for (const k of ['blocks', 'lastTime', 'lastDhat']) delete scope.dataset[k];
  bench.fit = null; showFit();
}

function onBlock(b) {
  const rate = 1 / b.dt;
  const cap = Math.ceil(kMaxBufferS * rate);
  if (bench.names.join() !== b.names.join() || !bench.time || bench.time.a.length !== cap) {
    bench.names = b.names; bench.buffers = {};
    for (const n of b.names) bench.buffers[n] = new Ring(cap);
    bench.time = bench.buffers['t_s'];
    buildPlots();
  }
  for (let c = 0; c < b.names.length; c++) {
    const ring = bench.buffers[b.names[c]];
    for (const v of b.columns[c]) ring.push(v === null ? NaN : v);
  }
  bench.blocks++;
  const d = bench.buffers['d_hat_n'] || bench.buffers['d_hat_q31'];
  if (d && d.n) bench.lastDhat = d.at(d.n - 1);
  const scope = document.getElementById('scope');
  scope.dataset.blocks = bench.blocks;
  scope.dataset.lastTime = bench.time.at(bench.time.n - 1);
  if (bench.lastDhat !== null) scope.dataset.lastDhat = bench.lastDhat;
  bench.dirty = true;
}

function showFit() {
  const f = bench.fit;
  const t = document.getElementById('fit');
  if (!f) { rows(t, [['fit', 'no fit yet: start an acquisition with d̂ and a load cell to fit against']]); return; }
  if (f.refusal) { rows(t, [['fit', f.refusal]]); return; }
  rows(t, [['fit', fmt(f.fit_percent) + ' %'], ['correlation', fmt(f.correlation, 5)],
           ['delay', fmt(f.delay_s * 1000) + ' ms'], ['rmse', fmt(f.rmse_n) + ' N'],
           ['window', fmt(f.window_s, 3) + ' s of ' + f.measured],
           ['d̂', f.lowpass_hz ? 'zero-phase low-pass at ' + fmt(f.lowpass_hz) + ' Hz (as dob run --lowpass-hz)' : 'raw']]);
  t.dataset.fitPercent = f.fit_percent;
  t.dataset.windowS = f.window_s;
}

function connect() {
  const es = new access.LiveChannel();
  const ls = document.getElementById('link-state');
  bench.live = es;  // views listen on the same channel
  es.addEventListener('open', () => { ls.textContent = 'live'; ls.className = 'muted'; });
  es.addEventListener('error', () => { ls.textContent = 'reconnecting…'; });
  // The server's reason, e.g. every live channel it serves is taken (it tries again).
  es.addEventListener('refused', e => {
    ls.textContent = 'no live data: ' + e.detail + ' (trying again)'; ls.className = 'error';
  });
  es.addEventListener('state', e => onState(JSON.parse(e.data)));
  es.addEventListener('block', e => onBlock(JSON.parse(e.data)));
  es.addEventListener('fit', e => { bench.fit = JSON.parse(e.data); showFit(); });
}

// ---- plots -------------------------------------------------------------------------------------

function plotWidth(el) { return Math.max(300, el.clientWidth - 10); }

function buildPlots() {
  for (const p of bench.plots) p.u.destroy();
  bench.plots = [];
  const scope = document.getElementById('scope');
  scope.replaceChildren();
  const channels = bench.names.filter(n => n !== 't_s' && !(n === 'd_hat_q31' && bench.names.includes('d_hat_n')));
  const colors = ['#1f77b4', '#d62728', '#2ca02c', '#9467bd', '#ff7f0e', '#8c564b', '#17becf'];
  channels.forEach((name, i) => {
    bench.plots.push(makePlot(scope, [name], label(name), [colors[i % colors.length]], 150));
  });
  const obs = document.getElementById('observer-plot');
  obs.replaceChildren();
  const measured = bench.state?.ask?.fit_measured;
  const force = measured ? bench.names.find(n => n.startsWith(measured + '_')) : null;
  const dhat = bench.names.includes('d_hat_n') ? 'd_hat_n' : null;
  if (dhat && force) bench.plots.push(makePlot(obs, [force, dhat], 'force (N)', ['#555', '#d62728'], 360));
}

// "force1_n" -> "force1 (N)", "d_hat_n" -> "d̂ (N)"
function label(column) {
  const stem = column.startsWith('d_hat') ? 'd̂' : column.split('_')[0];
  return stem + ' (' + unitOf(column) + ')';
}

function makePlot(parent, columns, axisLabel, colors, height) {
  const div = document.createElement('div');
  parent.append(div);
  const series = [{}];
  columns.forEach((c, i) => series.push({label: label(c), stroke: colors[i], width: 1, points: {show: false}}));
  const u = new uPlot({
    width: plotWidth(parent), height, legend: {show: columns.length > 1, live: false},
    cursor: {show: false}, scales: {x: {time: false}},
    axes: [{space: 60}, {label: axisLabel, size: 70, space: 25}], series,
  }, [[], ...columns.map(() => [])], div);
  return {u, columns, parent};
}

// min and max of each pixel column of the window [t_end - T, t_end]: 2 points per column.
function decimate(columns, width, span) {
  const t = bench.time;
  const n = t.n;
  const tEnd = t.at(n - 1);
  const tStart = tEnd - span;
  let i0 = 0, lo = 0, hi = n - 1;
  while (lo <= hi) { const m = (lo + hi) >> 1; if (t.at(m) < tStart) lo = m + 1; else hi = m - 1; }
  i0 = lo;
  const xs = [], ys = columns.map(() => []);
  const per = span / width;
  let i = i0;
  for (let px = 0; px < width && i < n; px++) {
    const edge = tStart + (px + 1) * per;
    const mins = columns.map(() => Infinity), maxs = columns.map(() => -Infinity);
    let tmin = NaN, tmax = NaN, count = 0;
    for (; i < n && (t.at(i) < edge || px === width - 1); i++) {
      const ti = t.at(i);
      if (count === 0) tmin = ti;
      tmax = ti; count++;
      for (let c = 0; c < columns.length; c++) {
        const v = bench.buffers[columns[c]].at(i);
        if (v < mins[c]) mins[c] = v;
        if (v > maxs[c]) maxs[c] = v;
      }
    }
    if (count === 0) continue;
    xs.push(tmin, tmax);
    for (let c = 0; c < columns.length; c++) ys[c].push(mins[c], maxs[c]);
  }
  return [xs, ...ys];
}

function draw() {
  requestAnimationFrame(draw);
  bench.frames++;
  if (bench.paused || !bench.dirty || !bench.time || !bench.time.n) return;
  bench.dirty = false;
  const span = Number(document.getElementById('timebase').value);
  for (const p of bench.plots) {
    if (p.parent.offsetParent === null) continue;  // a hidden view
    const w = plotWidth(p.parent);
    if (Math.abs(p.u.width - w) > 2) p.u.setSize({width: w, height: p.u.height});
    p.u.setData(decimate(p.columns, w, span));
  }
}

// ---- calibration view --------------------------------------------------------------------------

const listOf = id => document.getElementById(id).value.split(',').map(x => x.trim()).filter(x => x);

// "1=mass1.csv, 2=mass2.csv" as the identify request's mass tests (the server checks them).
function massTests() {
  return listOf('id-mass').map(t => {
    const [pos, file] = t.split('=');
    return {position: Number(pos), file: (file || '').trim()};
  });
}

// A verdict box above what it judges: the level in its colour, each reason on its line (the
// library decided them; the page only draws). `lead` says what the level means here.
function showVerdict(id, v, lead) {
  const box = document.getElementById(id);
  box.className = 'verdict verdict-' + v.level;
  box.dataset.level = v.level;
  const head = document.createElement('strong');
  head.textContent = 'Verdict: ' + v.level.toUpperCase() + (lead ? ' — ' + lead : '');
  const list = document.createElement('ul');
  for (const r of v.reasons) {
    const li = document.createElement('li');
    li.textContent = r.text; li.dataset.code = r.code; list.append(li);
  }
  if (v.stated === false) {
    const li = document.createElement('li');
    li.textContent = 'the model file states no verdict (written by hand, or before files carried one)';
    list.append(li);
  }
  box.replaceChildren(head, list);
  box.hidden = false;
}

async function identifyRun() {
  const status = document.getElementById('id-status');
  progress('id-run-status', 'identifying…');
  const request = {
    nominal: document.getElementById('id-nominal').value.trim(),
    mass_tests: massTests(), modal_tests: listOf('id-modal'),
    output: document.getElementById('id-output').value.trim()};
  if (document.getElementById('id-accept').checked) request.accept_flagged = true;
  // Left empty: no exponential window (identify's default); otherwise its value at each record's
  // end, as `vibid identify --exp-window` takes it.
  const exp = document.getElementById('id-exp').value.trim();
  if (exp !== '') request.exp_window = Number(exp);
  const r = await api('/api/cal/identify', request);
  document.getElementById('id-table').textContent = r.table;
  const fmt = (v, ci) => Number(v.toPrecision(6)) +
    (Array.isArray(ci) ? ' (95 %: ' + Number(ci[0].toPrecision(5)) + ' .. ' + Number(ci[1].toPrecision(5)) + ')' : ' (95 %: n/a)');
  rows(document.getElementById('id-params'), r.parameters.flatMap(p => [
    ['m' + p.position, fmt(p.m_kg, p.m_kg_ci95) + ' kg'],
    ['k' + p.position, fmt(p.k_n_per_m, p.k_n_per_m_ci95) + ' N/m']]));
  const level = r.verdict.level;
  showVerdict('id-verdict', r.verdict,
    level === 'flagged' ? (r.written ? 'written on your accept; do not take it to the board unasked'
                                     : 'not written: ' + r.not_written)
    : level === 'caution' ? 'written; usable, but read the reasons' : 'written');
  status.textContent = (r.written ? 'wrote ' + r.output : 'did not write ' + r.output) +
    (r.warnings.length ? '; ' + r.warnings.join('; ') : '');
  const st = document.getElementById('id-run-status');
  st.textContent = level === 'ok' ? 'identified' : 'identified: ' + level.toUpperCase();
  st.className = level === 'ok' ? 'muted' : 'verdict-text-' + level;
  status.dataset.parameters = JSON.stringify(r.parameters);
  if (!r.written) return;
  document.getElementById('design-model').value = r.output;
  document.getElementById('cal-model').value = r.output;
}

async function designRun() {
  const body = {model: document.getElementById('design-model').value.trim(),
                output: document.getElementById('design-output').value.trim()};
  const fs = document.getElementById('design-force-fs').value.trim();
  if (fs) body.force_fs_n = Number(fs);
  if (document.getElementById('design-accept').checked) body.accept_flagged = true;
  progress('design-status', 'designing…');
  const r = await api('/api/cal/design', body);
  progress('design-status', 'designed');
  document.getElementById('design-summary').textContent =
    'wrote ' + r.output + ' (force full scale ' + r.force_fs_n + ' N, ' + r.fs_hz + ' Hz)\n' + r.summary;
  document.getElementById('design-summary').dataset.checksum = String(r.checksum);
  if (r.verdict.level !== 'ok')
    document.getElementById('design-summary').textContent += '\nmodel ' + r.verdict.text;
  document.getElementById('cal-design').value = r.output;
}

function calFiles() {
  const f = {};
  for (const [key, id] of [['model', 'cal-model'], ['design', 'cal-design'], ['sensors', 'cal-sensors'], ['label', 'cal-label']]) {
    const v = document.getElementById(id).value.trim();
    if (v) f[key] = v;
  }
  return f;
}

const brief = v => v === null || v === undefined ? '—'
  : typeof v === 'object' ? JSON.stringify(v, (k, x) => typeof x === 'number' ? Number(x.toPrecision(6)) : x)
  : String(v);

async function calPreview() {
  const status = document.getElementById('cal-status');
  const p = await api('/api/cal/preview', calFiles());
  const t = document.getElementById('cal-changes');
  const head = document.createElement('tr');
  for (const h of ['', 'on the board now', 'after the commit']) {
    const th = document.createElement('th'); th.textContent = h; head.append(th);
  }
  const body = p.changes.map(c => {
    const tr = document.createElement('tr');
    for (const v of [c.field, brief(c.from), brief(c.to)]) {
      const td = document.createElement('td'); td.textContent = v; tr.append(td);
    }
    return tr;
  });
  t.replaceChildren(head, ...body);
  t.dataset.changes = p.changes.length;
  // A flagged model is offered for the board only on an explicit accept: the box, unticked.
  const flagged = p.verdict.level === 'flagged';
  showVerdict('cal-verdict', p.verdict, flagged
    ? 'vibid distrusts this model: upload and commit need your explicit accept below'
    : p.verdict.level === 'caution' ? 'usable, but read the reasons before you upload' : '');
  const accept = document.getElementById('cal-accept');
  accept.checked = false;
  document.getElementById('cal-accept-row').hidden = !flagged;
  bench.calFlagged = flagged;
  document.getElementById('cal-upload').disabled = flagged;
  document.getElementById('cal-commit').disabled = true;
  status.textContent = p.changes.length ? p.changes.length + ' fields change' : 'nothing changes';
}

// The accept box of a flagged model opens the upload; unticked again, it closes both steps.
function calAcceptChanged() {
  const on = document.getElementById('cal-accept').checked;
  document.getElementById('cal-upload').disabled = bench.calFlagged && !on;
  if (bench.calFlagged && !on) document.getElementById('cal-commit').disabled = true;
}

function calAccepted(body) {
  if (bench.calFlagged && document.getElementById('cal-accept').checked) body.accept_flagged = true;
  return body;
}

async function calUpload() {
  const r = await api('/api/cal/upload', calAccepted(calFiles()));
  document.getElementById('cal-status').textContent = 'staged ' + r.staged + ' (crc ' + r.crc32 + ')' +
    (r.verdict.level === 'ok' ? '' : ', model ' + r.verdict.level.toUpperCase()) + ': commit writes it to flash';
  document.getElementById('cal-commit').disabled = false;
}

async function calCommit() {
  const r = await api('/api/cal/commit', calAccepted({}));
  const s = document.getElementById('cal-status');
  s.textContent = 'committed to slot ' + r.slot + ', sequence ' + r.sequence +
    (r.verdict && r.verdict.level !== 'ok' ? ' (model ' + r.verdict.level.toUpperCase() + ')' : '');
  s.dataset.committed = r.sequence;
  document.getElementById('cal-upload').disabled = true;
  document.getElementById('cal-commit').disabled = true;
  await loadBoard();
}

// ---- controls ----------------------------------------------------------------------------------

function showView(id) {
  document.querySelectorAll('#tabs button').forEach(b => b.classList.toggle('active', b.dataset.view === id));
  document.querySelectorAll('.view').forEach(v => v.classList.toggle('active', v.id === 'view-' + id));
  bench.dirty = true;
}

async function loadViews() {
  // Views registered on the server (BenchServer::AddView): a tab, a section, a script.
  for (const v of await api('/api/views')) {
    const b = document.createElement('button');
    b.dataset.view = v.id; b.textContent = v.title;
    document.getElementById('tabs').append(b);
    const s = document.createElement('section');
    s.id = 'view-' + v.id; s.className = 'view'; s.innerHTML = v.html;
    document.querySelector('main').append(s);
    const script = document.createElement('script');
    script.src = '/views/' + v.id + '.js';
    document.body.append(script);
  }
  document.querySelectorAll('#tabs button').forEach(b => b.addEventListener('click', () => showView(b.dataset.view)));
}

function progress(id, text) {
  const e = document.getElementById(id);
  e.textContent = text; e.className = 'muted';
}

// A step's outcome beside its button: its progress, then its result or its error (which
// replaces the progress). A step that succeeds clears the banner of an earlier failure.
function wire(id, action, statusId) {
  document.getElementById(id).addEventListener('click', async () => {
    const st = document.getElementById(statusId);
    try {
      await action();
      say('', false);
    } catch (e) {
      st.textContent = e.message; st.className = 'error';
    }
  });
}

async function main() {
  await loadViews();
  await loadBoard();
  await updateBudget();
  document.getElementById('rate').addEventListener('change', logRates);
  ['rate', 'log-rate', 'seconds', 'log-dob', 'fit-measured'].forEach(id =>
    document.getElementById(id).addEventListener('change', updateBudget));
  document.getElementById('scenario').addEventListener('change', scenarioHint);
  scenarioHint();
  wire('start', async () => { await api('/api/acquire', ask()); progress('acq-msg', 'acquisition started'); }, 'acq-msg');
  wire('stop', async () => { await api('/api/stop', {}); progress('acq-msg', 'stopping: the records so far are kept'); }, 'acq-msg');
  wire('dob-on', async () => { await api('/api/observer', {run: true}); progress('acq-msg', 'observer on'); await loadBoard(); }, 'acq-msg');
  wire('dob-off', async () => { await api('/api/observer', {run: false}); progress('acq-msg', 'observer off'); await loadBoard(); }, 'acq-msg');
  wire('id-run', identifyRun, 'id-run-status');
  wire('design-run', designRun, 'design-status');
  wire('cal-preview', calPreview, 'cal-status');
  wire('cal-upload', calUpload, 'cal-status');
  wire('cal-commit', calCommit, 'cal-status');
  document.getElementById('cal-accept').addEventListener('change', calAcceptChanged);
  document.getElementById('pause').addEventListener('click', e => {
    bench.paused = !bench.paused; e.target.textContent = bench.paused ? 'Resume' : 'Pause'; bench.dirty = true;
  });
  document.getElementById('timebase').addEventListener('change', () => { bench.dirty = true; });
  showFit();
  connect();
  requestAnimationFrame(draw);
  document.body.dataset.ready = 'yes';
}

main().catch(e => say(e.message, true));
