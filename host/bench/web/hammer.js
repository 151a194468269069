// The hammer test view: settings and their link budget, the hits with the server's verdicts and
// the operator's choice, the selected hit's record, H1 and coherence over the accepted hits, the
// stabilization diagram and the modes. Everything drawn is what the server computed
// (workflow::HammerSession); the page only lays it out.
'use strict';
(() => {
const hm = {
  test: null, snap: null, sel: null, traces: null,
  plots: {}, latencies: [], pendingArrival: null, events: 0,
};
window.hammer = hm;
hm.settings = () => settings();  // what Start would send (the browser test compares it)
const $ = id => document.getElementById(id);

async function post(path, body) {
  const r = await fetch('/api/hammer/' + path, {method: 'POST', headers: access.headers({'Content-Type': 'application/json'}),
                                                 body: JSON.stringify(body || {})});
  const j = await r.json().catch(() => ({error: 'HTTP ' + r.status}));
  if (!r.ok) throw new Error(j.error || ('HTTP ' + r.status));
  return j;
}
function status(text, error) { const s = $('hm-status'); s.textContent = text; s.className = error ? 'error' : 'muted'; }

// An empty field is left out: the server takes the library's default (vibid frf-estimate's).
const optional = [['hm-record', 'record_s'], ['hm-trigger', 'trigger'], ['hm-pretrigger', 'pretrigger_s'],
                  ['hm-fwin', 'force_window_s'], ['hm-exp', 'exp_window']];
function settings() {
  const responses = [...document.querySelectorAll('#hm-responses input:checked')].map(i => i.value);
  const s = {
    channels: [$('hm-force').value, ...responses],
    sample_period_us: Number($('hm-rate').value),
    seconds: Number($('hm-seconds').value),
    hammer_point: $('hm-point').value,
  };
  for (const [id, key] of optional) if ($(id).value !== '') s[key] = Number($(id).value);
  // On the emulator the hammer scenario always runs: empty parameters are its defaults.
  if (window.bench && bench.board && bench.board.identity.emulator) {
    s.scenario = 'hammer';
    const params = $('hm-params').value.trim();
    if (params) s.scenario_params = params.split(/[\s,]+/).map(Number);
  }
  return s;
}

async function preflight() {
  const p = $('hm-preflight');
  try {
    const b = await post('preflight', settings());
    // The device library's budget lines, as the board view's box shows them.
    p.textContent = 'link budget: ' + b.lines.map(([k, v]) => k + ' ' + v).join('; ') + (b.refusal ? ' — ' + b.refusal : '');
    p.className = b.refusal ? 'error' : 'muted';
  } catch (e) { p.textContent = e.message; p.className = 'error'; }
}

// ---- plots -------------------------------------------------------------------------------------

const colors = ['#1f77b4', '#d62728', '#2ca02c', '#9467bd'];
function width(el) { return Math.max(260, el.clientWidth - 6); }

function plot(key, el, opts, data) {
  const p = hm.plots[key];
  const sig = JSON.stringify(opts.series.map(s => s.label)) + (opts.tag || '');
  if (p && p.sig === sig && el.offsetParent !== null) {
    const w = width(el);
    if (Math.abs(p.u.width - w) > 2) p.u.setSize({width: w, height: p.u.height});
    p.u.setData(data);
    return p.u;
  }
  if (p) p.u.destroy();
  el.replaceChildren();
  const u = new uPlot(Object.assign({width: width(el), cursor: {show: false}}, opts), data, el);
  hm.plots[key] = {u, sig};
  return u;
}

function drawTraces() {
  const t = hm.traces;
  if (!t) return;
  $('hm-hit-title').textContent = t.index;
  // The force up to four times the window's length: the pulse and its taper, readable.
  let last = 0;
  t.force_window.forEach((w, i) => { if (w > 0) last = i; });
  const xMax = Math.min(t.t_s[t.t_s.length - 1], Math.max(4 * t.t_s[last], 0.02));
  plot('force', $('hm-force-plot'), {
    height: 150, tag: String(xMax), scales: {x: {time: false, range: () => [t.t_s[0], xMax]}, w: {range: [0, 1.05]}},
    axes: [{}, {label: 'N', size: 60}, {scale: 'w', side: 1, label: 'window', size: 50}],
    series: [{}, {label: 'force', stroke: '#333', width: 1, points: {show: false}},
             {label: 'window', stroke: '#ff7f0e', width: 1.5, scale: 'w', points: {show: false}}],
    legend: {show: true, live: false},
  }, [t.t_s, t.force, t.force_window]).setScale('x', {min: t.t_s[0], max: xMax});
  plot('resp', $('hm-resp-plot'), {
    height: 150, scales: {x: {time: false}}, axes: [{label: 't from the trigger (s)'}, {label: t.responses[0].name.replace(/^[a-z0-9]+_/, ''), size: 60}],
    series: [{}, ...t.responses.map((r, i) => ({label: r.name, stroke: colors[i % 4], width: 1, points: {show: false}}))],
    legend: {show: true, live: false},
  }, [t.t_s, ...t.responses.map(r => r.values)]);
}

function drawFrf() {
  const f = hm.snap && hm.snap.frf;
  const keys = ['mag', 'phase', 'coh'];
  if (!f) { keys.forEach(k => { if (hm.plots[k]) { hm.plots[k].u.destroy(); delete hm.plots[k]; } $('hm-' + k).replaceChildren(); }); return; }
  // Lines above 0 Hz on a logarithmic frequency axis: the band the modes were identified in
  // (the snapshot's band_hz), or every line on request.
  const band = $('hm-all-lines').checked ? null : hm.snap.band_hz;
  let i0 = 1, i1 = f.freq_hz.length;
  if (band) {
    while (i0 < i1 && f.freq_hz[i0] < band[0]) i0++;
    while (i1 > i0 + 1 && f.freq_hz[i1 - 1] > band[1]) i1--;
  }
  const x = f.freq_hz.slice(i0, i1);
  $('hm-mag').dataset.xMax = x[x.length - 1];
  $('hm-mag').dataset.band = band ? band.join(',') : 'all';
  const series = f.responses.map((r, i) => ({label: r.name, stroke: colors[i % 4], width: 1, points: {show: false}}));
  const exp = (u, vals) => vals.map(v => v === null ? '' : Number(v).toExponential(0));
  const base = (label, yScale, log) => ({height: 170, legend: {show: true, live: false}, tag: label,
    scales: {x: {time: false, distr: 3}, y: yScale},
    axes: [{label: 'Hz'}, Object.assign({label, size: 70}, log ? {values: exp} : {})], series: [{}, ...series]});
  const positive = v => v > 0 ? v : null;
  const mag = plot('mag', $('hm-mag'), Object.assign(base(f.kind === 'receptance' ? 'm/N' : f.kind, {distr: 3}, true), {hooks: {draw: [u => {
    if (hm.pendingArrival !== null) {
      hm.latencies.push(performance.timeOrigin + performance.now() - hm.pendingArrival);
      hm.pendingArrival = null;
      $('hm-mag').dataset.latencies = hm.latencies.length;
    }
  }]}}), [x, ...f.responses.map(r => r.magnitude.slice(i0, i1).map(positive))]);
  plot('phase', $('hm-phase'), base('°', {range: [-180, 180]}), [x, ...f.responses.map(r => r.phase_rad.slice(i0, i1).map(v => v * 180 / Math.PI))]);
  plot('coh', $('hm-coh'), base('γ²', {range: [0, 1.05]}), [x, ...f.responses.map(r => r.coherence.slice(i0, i1))]);
  return mag;
}

function drawDiagram() {
  const d = hm.snap && hm.snap.diagram;
  const el = $('hm-stab');
  if (!d) { if (hm.plots.stab) { hm.plots.stab.u.destroy(); delete hm.plots.stab; } el.replaceChildren(); return; }
  const [lo, hi] = d.band_hz;
  const poles = d.poles.filter(p => p.freq_hz >= lo && p.freq_hz <= hi).sort((a, b) => a.freq_hz - b.freq_hz);
  const stable = p => p.stable_freq && p.stable_damping;
  // The band's ends as points without a value: the frequency axis spans the band searched.
  const col = f => [null, ...poles.map(f), null];
  plot('stab', el, {
    height: 230, legend: {show: true, live: false},
    scales: {x: {time: false}, y: {range: [0, Math.max(...d.orders) + 2]}},
    axes: [{label: 'Hz'}, {label: 'model order', size: 60}],
    series: [{}, {label: 'stable', stroke: '#2ca02c', fill: '#2ca02c', paths: () => null, points: {show: true, size: 7}},
             {label: 'not stable', stroke: '#aaa', paths: () => null, points: {show: true, size: 4}},
             {label: 'chosen', stroke: '#d62728', paths: () => null, points: {show: true, size: 11, width: 2}}],
  }, [[lo, ...poles.map(p => p.freq_hz), hi], col(p => stable(p) ? p.order : null), col(p => stable(p) ? null : p.order),
      col(p => d.selected.some(s => s.freq_hz === p.freq_hz) ? p.order : null)]);
}

// ---- tables ------------------------------------------------------------------------------------

function cell(tr, text, cls) { const td = document.createElement('td'); td.textContent = text; if (cls) td.className = cls; tr.append(td); return td; }
const num = (v, d) => v === null || v === undefined ? '—' : Number(v).toPrecision(d);
function pm(v, ci, d) {
  if (v === null || v === undefined) return '—';
  return Number(v).toPrecision(d) + (ci ? ' ± ' + Number((ci[1] - ci[0]) / 2).toPrecision(2) : ' ± n/a');
}

function drawHits() {
  const s = hm.snap;
  const t = $('hm-hits');
  const head = document.createElement('tr');
  for (const h of ['#', 't s', 'peak N', 'verdict', 'used', '']) { const th = document.createElement('th'); th.textContent = h; head.append(th); }
  const rows = (s ? s.hits : []).map(h => {
    const tr = document.createElement('tr');
    tr.dataset.index = h.index; tr.dataset.verdict = h.verdict; tr.dataset.accepted = h.accepted;
    if (h.index === hm.sel) tr.className = 'sel';
    cell(tr, h.index); cell(tr, num(h.t_s, 4)); cell(tr, num(h.peak_n, 4));
    cell(tr, h.verdict + (h.reason && h.reason !== h.verdict ? ': ' + h.reason : ''), h.verdict === 'ok' ? '' : 'rej');
    cell(tr, (h.accepted ? 'yes' : 'no') + (h.decided_by === 'operator' ? ' (operator)' : ''));
    const td = cell(tr, '', 'hm-choice');
    for (const [label, accept] of [['Accept', true], ['Reject', false]]) {
      const b = document.createElement('button'); b.type = 'button'; b.textContent = label;
      b.className = accept ? 'hm-accept' : 'hm-reject';
      b.addEventListener('click', ev => { ev.stopPropagation(); choose(h.index, accept); });
      td.append(b, ' ');
    }
    tr.addEventListener('click', () => select(h.index));
    return tr;
  });
  t.replaceChildren(head, ...rows);
  $('hm-count').textContent = s ? '(' + s.accepted + ' accepted of ' + s.hits.length + (s.pending_hits ? ', ' + s.pending_hits + ' pending' : '') + ')' : '';
  t.dataset.hits = s ? s.hits.length : 0;
}

function drawModes() {
  const s = hm.snap;
  const t = $('hm-modes');
  const head = document.createElement('tr');
  const modes = (s && s.modes) || [];
  // Two responses: a1/a2; more: each response's amplitude over the driving point's (the
  // library's shape_ratio, 1 at the driving point, which has no interval).
  const many = modes.some(m => (m.shape_ratio || []).length > 2);
  for (const h of ['mode', 'f Hz', 'ω rad/s (95 %)', 'ζ (95 %)', many ? 'shape a_k/a_dp (95 %)' : 'a1/a2 (95 %)']) { const th = document.createElement('th'); th.textContent = h; head.append(th); }
  t.replaceChildren(head, ...modes.map((m, i) => {
    const tr = document.createElement('tr');
    const ci = m.ci95 || {};
    cell(tr, i + 1); cell(tr, num(m.freq_hz, 6)); cell(tr, pm(m.omega_rad_s, ci.omega_rad_s, 6));
    cell(tr, pm(m.zeta, ci.zeta, 4));
    if (many) {
      const r = m.shape_ratio || [], rci = ci.shape_ratio || [];
      cell(tr, r.map((v, k) => v === 1 && !rci[k] ? '1' : pm(v, rci[k], 4)).join('; '));
    } else {
      cell(tr, pm(m.ratio, ci.ratio, 5));
    }
    return tr;
  }));
  t.dataset.modes = JSON.stringify(modes);
  $('hm-modes-note').textContent = s ? (s.modes_error || (s.modes ? 'after ' + s.accepted + ' accepted hits; modes in ' + num(s.timing_ms.modes, 3) + ' ms' : '')) : '';
}

function drawStatus() {
  const t = hm.test, s = hm.snap;
  // Until the first snapshot has answered, the page does not know: it says so, not "none".
  if (!t) { status(hm.read ? 'no hammer test yet' : 'reading the hammer test…'); return; }
  const line = t.name + (t.running ? ': running, ' : ': ended, ') + (s ? (s.samples / s.fs_hz).toFixed(1) + ' s sampled' : '') +
    (t.saved ? '; saved in ' + t.dir : '');
  status(t.error ? line + ' — ' + t.error : line, !!t.error);
  // Every warning the library gives (the estimation's and the modes'), as vibid modes prints them.
  const w = $('hm-warnings');
  const list = s ? s.warnings : [];
  w.replaceChildren(...list.map(x => { const li = document.createElement('li'); li.textContent = 'warning: ' + x; return li; }));
  w.dataset.warnings = JSON.stringify(list);
  document.body.dataset.hammer = t.running ? 'running' : 'ended';
}

function onFull(j) {
  hm.events++;
  // An answer and the live event of the same change may cross: an older state never replaces a newer one.
  if (j.test && hm.test && hm.snap && j.test.name === hm.test.name && j.snapshot.version < hm.snap.version) return;
  // Another test on screen (a new start, here or in another tab): its own settings in the form,
  // and nothing of the last one's hits, selection or record left beside them.
  const changed = j.test && (!hm.test || j.test.name !== hm.test.name);
  hm.test = j.test; hm.snap = j.snapshot;
  if (!hm.test) { drawStatus(); return; }
  if (changed) {
    hm.sel = null; hm.traces = null;
    for (const k of ['force', 'resp']) { if (hm.plots[k]) { hm.plots[k].u.destroy(); delete hm.plots[k]; } }
    $('hm-force-plot').replaceChildren(); $('hm-resp-plot').replaceChildren(); $('hm-hit-title').textContent = '';
    showSettings(hm.test.settings);
    preflight();
  }
  const hits = hm.snap.hits;
  // Follow the newest hit unless the operator moved away from it.
  if (hits.length && (hm.sel === null || hm.sel === hits.length - 1 || hm.sel > hits.length)) {
    if (hm.sel !== hits.length) select(hits.length);
  }
  if (j.arrived_ms !== null && j.arrived_ms !== undefined && hm.snap.frf) hm.pendingArrival = j.arrived_ms;
  drawStatus(); drawHits(); drawModes(); drawFrf(); drawDiagram();
  $('hm-status').dataset.version = hm.snap.version;
}

async function select(index) {
  hm.sel = index;
  drawHits();
  try { hm.traces = await post('traces', {index}); drawTraces(); } catch (e) { status(e.message, true); }
}

async function choose(index, accept) {
  try { onFull(await post('choose', {index, accept})); } catch (e) { status(e.message, true); }
}

// The form shows the settings of the test on screen (after a reload: the running one's).
function showSettings(s) {
  $('hm-rate').value = s.sample_period_us; $('hm-force').value = s.channels[0];
  document.querySelectorAll('#hm-responses input').forEach(i => { i.checked = s.channels.slice(1).includes(i.value); });
  $('hm-point').value = s.hammer_point; $('hm-seconds').value = s.seconds;
  for (const [id, key] of optional) $(id).value = s[key] === undefined ? '' : s[key];
  $('hm-params').value = (s.scenario_params || []).join(', ');
  $('hm-form').dataset.shows = JSON.stringify(s);
}

async function refresh() {
  onFull(await post('snapshot', {}));
  hm.read = true;
  drawStatus();
}

function keys(ev) {
  if (!$('view-hammer').classList.contains('active') || !hm.snap || !hm.snap.hits.length) return;
  if (['INPUT', 'SELECT', 'TEXTAREA'].includes(ev.target.tagName)) return;
  const n = hm.snap.hits.length, i = hm.sel || 1;
  if (ev.key === 'ArrowDown' || ev.key === 'j') select(Math.min(n, i + 1));
  else if (ev.key === 'ArrowUp' || ev.key === 'k') select(Math.max(1, i - 1));
  else if (ev.key === 'a') choose(i, true);
  else if (ev.key === 'r') choose(i, false);
  else return;
  ev.preventDefault();
}

function listen() {
  if (!window.bench || !bench.live) { setTimeout(listen, 50); return; }
  bench.live.addEventListener('hammer', e => onFull(JSON.parse(e.data)));
  bench.live.addEventListener('hammer-progress', e => {
    const p = JSON.parse(e.data);
    if (hm.snap && hm.test && hm.test.running) { hm.snap.samples = p.samples; hm.snap.pending_hits = p.pending_hits; drawStatus(); }
  });
  // After a reconnect (the server restarted its stream) the state is fetched again.
  bench.live.addEventListener('open', () => refresh().catch(e => status(e.message, true)));
}

function wire(id, action) {
  $(id).addEventListener('click', async () => { try { await action(); } catch (e) { status(e.message, true); } });
}

wire('hm-start', async () => { onFull(await post('start', settings())); });
wire('hm-stop', async () => { await post('stop', {}); });
wire('hm-save', async () => { const r = await post('save', {}); $('hm-save').dataset.dir = r.dir; status('saved ' + r.files.join(', ') + ' in ' + r.dir); });
document.querySelectorAll('#hm-form input, #hm-form select').forEach(e => e.addEventListener('change', preflight));
$('hm-all-lines').addEventListener('change', () => drawFrf());
document.addEventListener('keydown', keys);
document.querySelector('#tabs').addEventListener('click', () => setTimeout(() => { if (hm.snap) { drawFrf(); drawDiagram(); drawTraces(); } }, 0));
preflight();
refresh().then(() => { $('view-hammer').dataset.ready = 'yes'; }).catch(e => status(e.message, true));
listen();
})();
