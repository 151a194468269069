// The Watch view: the rig watched on the board by the library's runner (workflow::WatchBoardRun,
// as `vibid watch --device` runs it). Per block: the trends of each mode's frequency and damping
// with their 95 % intervals, the block's T² (beside its F quantile) and the window's against its threshold, the alarm,
// the mode that moved, and the board's own model test. Everything drawn is what the server
// computed; the page only lays it out.
'use strict';
(() => {
const wt = {watch: null, blocks: [], plots: {}, dirty: false, events: 0};
window.watch = wt;
wt.settings = () => settings();  // what Start would send (the browser test reads it)
const $ = id => document.getElementById(id);
const TWO_PI = 2 * Math.PI;
// The page draws the last blocks, as many as the server keeps for it (12 h of 10 s blocks); the
// journal holds every one.
const kKeptBlocks = 4320;

async function post(path, body) {
  const r = await fetch('/api/watch/' + path, {method: 'POST', headers: access.headers({'Content-Type': 'application/json'}),
                                                body: JSON.stringify(body || {})});
  const j = await r.json().catch(() => ({error: 'HTTP ' + r.status}));
  if (!r.ok) throw new Error(j.error || ('HTTP ' + r.status));
  return j;
}
function status(text, error) { const s = $('wt-status'); s.textContent = text; s.className = error ? 'error' : 'muted'; }

// An empty field is left out: the server takes the library's default (vibid watch's).
const numeric = [['wt-rate', 'rate_hz'], ['wt-log-rate', 'log_rate_hz'], ['wt-seconds', 'seconds'],
                 ['wt-reference-s', 'reference_s'], ['wt-block', 'block_s'], ['wt-window', 'window_blocks'],
                 ['wt-far', 'false_alarm_per_hour'], ['wt-fmax', 'fmax_hz'], ['wt-modes', 'modes_s'], ['wt-order', 'order']];
function settings() {
  const s = {channels: [...document.querySelectorAll('#wt-channels input:checked')].map(i => i.value)};
  for (const [id, key] of numeric) if ($(id).value !== '') s[key] = Number($(id).value);
  const ref = $('wt-reference').value.trim();
  if (ref) s.reference = ref;
  if ($('wt-no-dob').checked) s.no_dob = true;
  if (window.bench && bench.board && bench.board.identity.emulator) {
    if ($('wt-scenario').value) s.scenario = $('wt-scenario').value;
    const params = $('wt-params').value.trim();
    if (params) s.scenario_params = params.split(/[\s,]+/).map(Number);
  }
  return s;
}

function showSettings(s) {
  for (const [id, key] of numeric) $(id).value = s[key] === undefined ? '' : s[key];
  document.querySelectorAll('#wt-channels input').forEach(i => { i.checked = (s.channels || ['acc1', 'acc2']).includes(i.value); });
  $('wt-reference').value = s.reference || '';
  $('wt-no-dob').checked = s.no_dob === true;
  $('wt-scenario').value = s.scenario || '';
  $('wt-params').value = (s.scenario_params || []).join(', ');
  $('wt-form').dataset.shows = JSON.stringify(s);
}

// ---- tables and words --------------------------------------------------------------------------

const fmt = (v, d) => v === null || v === undefined ? '—' : Number(v).toPrecision(d);
const hz = w => w / TWO_PI;
function row(t, cells, head) {
  const tr = document.createElement('tr');
  for (const c of cells) { const td = document.createElement(head ? 'th' : 'td'); td.textContent = c; tr.append(td); }
  t.append(tr);
}

function boardWords(b, w) {
  // The board's flag with each block when its log carries its model test; else its get-info.
  if (b && b.board) {
    const g = b.board;
    return {stale: g.stale, text: (g.stale ? 'MODEL STALE since ' + fmt(g.stale_since_t_s, 5) + ' s' : 'in control') +
      ': g ' + fmt(g.statistic, 3) + (g.threshold ? ' of h ' + fmt(g.threshold, 3) : '') + ' (logged with the data)'};
  }
  const start = w && w.start, end = w && w.end;
  if (!start) return {stale: null, text: '—'};
  const info = end && end.model_text ? 'at the end: ' + end.model_text : start.model_text ? 'before the start: ' + start.model_text : '';
  if (!info) return {stale: null, text: 'no model test on the board (no observer running)'};
  const ms = end && end.model_stale ? end.model_stale : start.model_stale;
  return {stale: ms && ms.stale === true, text: 'no model test in the log; the board ' + info};
}

function drawCards() {
  const w = wt.watch, b = wt.blocks.length ? wt.blocks[wt.blocks.length - 1] : null;
  const v = $('wt-verdict');
  const first = b ? b.first_alarm_t_s : null;
  v.textContent = !b ? '—' : first !== null ? 'ALARM: changed (first alarm at ' + Number(first).toFixed(1) + ' s, block ' +
    (wt.blocks.find(x => x.alarm) || {}).block + ')' : 'no change';
  v.className = 'wt-big ' + (first !== null ? 'error' : b ? 'wt-ok' : 'muted');
  v.dataset.firstAlarm = first === null || first === undefined ? '' : first;
  const t = $('wt-tests'); t.replaceChildren();
  if (b) {
    const a = b.accumulated;
    row(t, ['block ' + b.block + ' at', fmt(b.t_s, 6) + ' s']);
    row(t, ['block T²', fmt(b.statistic, 3) + ' (F quantile ' + fmt(b.f_quantile, 3) + ', not a threshold' + (b.block_over ? '; over it: shown, not an alarm)' : ')')]);
    // A window is one test when full: a partial one shows its count, not a threshold.
    row(t, ['window T²', a.tested ? fmt(a.statistic, 3) + ' / ' + fmt(a.threshold, 3) + ' (' + a.window_blocks + ' blocks)' + (a.alarm ? ' ALARM' : '')
                                  : a.blocks + ' of ' + a.window_blocks + ' blocks, tested when full']);
    // The sequential test decides at every block; k is the onset that maximised its statistic.
    const q = b.sequential;
    row(t, ['sequential g', fmt(q.statistic, 3) + ' / ' + fmt(q.threshold, 3) + ' (onset ' + q.onset_blocks + ' blocks back)' + (q.alarm ? ' ALARM' : '')]);
  }
  const m = $('wt-moved'), mv = b && b.moved;
  m.textContent = mv ? movedWords(mv) : b ? (b.modes_message || 'no modes at this block') : '—';
  m.dataset.mode = mv ? mv.mode : '';
  m.dataset.quantity = mv ? mv.quantity : '';
  const mt = $('wt-modes'); mt.replaceChildren();
  if (b && b.modes.length) {
    row(mt, ['mode', 'f Hz (95 %)', 'ζ % (95 %)'], true);
    b.modes.forEach((x, i) => row(mt, [i + 1, fmt(hz(x.omega_rad_s), 5) + ' ± ' + fmt(hz(x.ci95.omega_rad_s), 2),
                                         fmt(100 * x.zeta, 3) + ' ± ' + fmt(100 * x.ci95.zeta, 2)]));
  }
  const bw = boardWords(b, w);
  $('wt-board').textContent = bw.text;
  $('wt-board').className = bw.stale ? 'error' : 'muted';
  $('wt-board').dataset.stale = bw.stale === null ? '' : String(bw.stale);
  $('wt-board-card').style.display = b && b.board ? '' : 'none';
  const r = $('wt-reference-state'), rt = $('wt-ref-modes'); rt.replaceChildren();
  if (w && w.reference) {
    const ref = w.reference;
    r.textContent = fmt(ref.seconds, 4) + ' s (' + (ref.source === 'recording' ? 'a reference recording' : 'watched') + ', ' +
      Number(ref.span.from_t_s.toPrecision(6)) + ' to ' + Number(ref.span.to_t_s.toPrecision(6)) + ' s): test order ' + ref.order + ', ' + ref.dof + ' residuals over ' + ref.reference_blocks +
      ' blocks; window threshold ' + fmt(ref.window_threshold, 3) + ': this reference gives between ' +
      fmt(ref.false_alarms_per_hour_95[0], 2) + ' and ' + fmt(ref.false_alarms_per_hour_95[1], 2) + ' false alarms per hour (95 %); sequential threshold ' +
      fmt(ref.sequential_threshold, 3) + ': between ' + fmt(ref.sequential_false_alarms_per_hour_95[0], 2) + ' and ' +
      fmt(ref.sequential_false_alarms_per_hour_95[1], 2) + ' false alarms per hour (95 %)';
    row(rt, ['mode', 'f Hz (95 %)', 'ζ % (95 %)'], true);
    ref.modes.forEach((x, i) => row(rt, [i + 1, fmt(hz(x.omega_rad_s), 5) + ' ± ' + fmt(hz(x.ci95.omega_rad_s), 2),
                                          fmt(100 * x.zeta, 3) + ' ± ' + fmt(100 * x.ci95.zeta, 2)]));
  } else if (w) {
    r.textContent = w.running ? 'the reference phase: ' + Math.ceil(w.reference_left_s) + ' s left of ' + fmt(w.options.reference_s, 4) +
      ' s (the rig as it is now)' : 'no reference built (' + fmt(w.reference_left_s, 4) + ' s of it were to go)';
  } else {
    r.textContent = '—';
  }
  r.dataset.left = w ? w.reference_left_s : '';
}

// What moved most against the reference (the server's choice): the quantity, its change and the
// change over its combined 95 % interval.
function movedWords(mv) {
  const sign = v => (v >= 0 ? '+' : '');
  const times = ' (' + mv.significance.toFixed(1) + '× its interval)';
  if (mv.quantity === 'zeta') {
    const z = mv.zeta;
    return 'mode ' + mv.mode + ' ζ: ' + fmt(100 * z.now, 3) + ' % against ' + fmt(100 * z.ref, 3) + ' % (' + sign(z.change) +
      fmt(100 * z.change, 2) + ' ± ' + fmt(100 * z.ci95, 2) + ' points)' + times;
  }
  if (mv.quantity === 'shape') {
    const s = mv.shape;
    return 'mode ' + mv.mode + ' shape: entry ' + s.entry + ' ' + sign(s.change) + fmt(s.change, 3) + ' ± ' + fmt(s.ci95, 2) +
      ', MAC ' + fmt(s.mac, 4) + times;
  }
  return 'mode ' + mv.mode + ' ω: ' + fmt(hz(mv.omega_rad_s), 5) + ' Hz against ' + fmt(hz(mv.omega_ref_rad_s), 5) +
    ' (' + sign(mv.relative) + (100 * mv.relative).toFixed(2) + ' %, ' + sign(mv.change_rad_s) +
    fmt(mv.change_rad_s, 3) + ' ± ' + fmt(mv.ci95_rad_s, 2) + ' rad/s)' + times;
}

function drawStatus() {
  const w = wt.watch;
  if (!w) { status('nothing watched yet'); document.body.dataset.watch = 'none'; return; }
  const n = wt.blocks.length ? wt.blocks[wt.blocks.length - 1].block : 0;
  let line = w.name + (w.running ? ': watching' : ': ended') + (w.start ? ' ' + w.start.responses.join(', ') + ' at ' + fmt(w.start.log_rate_hz, 4) + ' Hz' : '') +
    (w.running && !w.reference ? ', reference ' + Math.ceil(w.reference_left_s) + ' s left' : '') + '; ' + n + ' blocks; journal ' + w.journal;
  if (w.warning) line += ' — warning: ' + w.warning;
  status(w.error ? line + ' — ' + w.error : line, !!w.error);
  document.body.dataset.watch = w.running ? 'running' : 'ended';
  $('wt-status').dataset.blocks = n;
}

// ---- plots -------------------------------------------------------------------------------------

const colors = ['#1f77b4', '#d62728', '#2ca02c', '#9467bd', '#ff7f0e', '#8c564b'];
function width(el) { return Math.max(300, el.clientWidth - 6); }
function plot(key, el, opts, data) {
  const p = wt.plots[key];
  const sig = JSON.stringify(opts.series.map(s => s.label));
  if (p && p.sig === sig && el.offsetParent !== null) {
    const w = width(el);
    if (Math.abs(p.u.width - w) > 2) p.u.setSize({width: w, height: p.u.height});
    p.u.setData(data);
    return p.u;
  }
  if (p) p.u.destroy();
  el.replaceChildren();
  const u = new uPlot(Object.assign({width: width(el), cursor: {show: false}, legend: {show: true, live: false}}, opts), data, el);
  wt.plots[key] = {u, sig};
  return u;
}
const rgba = (c, a) => 'rgba(' + [1, 3, 5].map(i => parseInt(c.slice(i, i + 2), 16)).join(',') + ',' + a + ')';

// Each block's modes, matched to the reference's by frequency (a block may find fewer).
function matched(b, ref) {
  const out = ref.map(() => null);
  for (const m of b.modes) {
    let best = -1, d = Infinity;
    ref.forEach((r, i) => { const e = Math.abs(m.omega_rad_s / r.omega_rad_s - 1); if (e < d) { d = e; best = i; } });
    if (best >= 0 && d < 0.15 && out[best] === null) out[best] = m;
  }
  return out;
}

function drawModePlots() {
  const ref = wt.watch && wt.watch.reference ? wt.watch.reference.modes : [];
  const t = wt.blocks.map(b => b.t_s);
  const per = wt.blocks.map(b => matched(b, ref));
  const trend = (key, el, unit, value, ci, refValue, only) => {
    const series = [{}], data = [t], bands = [];
    ref.forEach((r, i) => {
      if (only !== undefined && i !== only) return;
      const c = colors[i % colors.length];
      const v = per.map(ms => ms[i] ? value(ms[i]) : null);
      const h = per.map(ms => ms[i] ? value(ms[i]) + ci(ms[i]) : null);
      const l = per.map(ms => ms[i] ? value(ms[i]) - ci(ms[i]) : null);
      const base = series.length;
      series.push({label: 'mode ' + (i + 1), stroke: c, width: 1.5, points: {show: true, size: 4}},
                  {label: 'band', stroke: rgba(c, 0.35), width: 0.5, points: {show: false}},
                  {label: 'band', stroke: rgba(c, 0.35), width: 0.5, points: {show: false}},
                  {label: 'mode ' + (i + 1) + ' ref', stroke: c, width: 1, dash: [6, 4], points: {show: false}});
      data.push(v, h, l, t.map(() => refValue(r)));
      bands.push({series: [base + 1, base + 2], fill: rgba(c, 0.18)});
    });
    const u = plot(key, el, {height: 200, bands, scales: {x: {time: false}}, series,
                             axes: [{label: 't (s)'}, {label: unit, size: 60}]}, data);
    // The bands' edges are no entries of their own in the legend.
    u.root.querySelectorAll('.u-legend .u-series').forEach(e => { if (e.textContent.trim() === 'band') e.style.display = 'none'; });
  };
  // One frequency plot per mode: a change of a few per cent shows on its own scale.
  const freq = $('wt-freq');
  if (freq.children.length !== ref.length) {
    for (const k of Object.keys(wt.plots)) if (k.startsWith('freq')) { wt.plots[k].u.destroy(); delete wt.plots[k]; }
    freq.replaceChildren(...ref.map(() => document.createElement('div')));
  }
  ref.forEach((r, i) => trend('freq' + i, freq.children[i], 'mode ' + (i + 1) + ': f (Hz)', m => hz(m.omega_rad_s),
                              m => hz(m.ci95.omega_rad_s), x => hz(x.omega_rad_s), i));
  freq.dataset.points = per.filter(ms => ms.some(m => m)).length;
  trend('zeta', $('wt-zeta'), 'ζ (%)', m => 100 * m.zeta, m => 100 * m.ci95.zeta, x => 100 * x.zeta);
}

function drawStatPlot() {
  const t = wt.blocks.map(b => b.t_s);
  const pos = v => v > 0 ? v : null;
  plot('stat', $('wt-stat'), {
    height: 230, scales: {x: {time: false}, y: {distr: 3}},
    axes: [{label: 't (s)'}, {label: 'T²', size: 60}],
    series: [{}, {label: 'block T²', stroke: '#999', width: 1, points: {show: true, size: 3}},
             {label: 'its F quantile (not a threshold)', stroke: '#999', dash: [4, 4], width: 1, points: {show: false}},
             {label: 'window T²', stroke: '#1f77b4', width: 2, points: {show: true, size: 4}},
             {label: 'its threshold', stroke: '#d62728', dash: [6, 4], width: 1.5, points: {show: false}},
             {label: 'alarm', stroke: '#d62728', paths: () => null, points: {show: true, size: 12, width: 2, fill: '#d62728'}}],
  }, [t, wt.blocks.map(b => pos(b.statistic)), wt.blocks.map(b => pos(b.f_quantile)),
      wt.blocks.map(b => pos(b.accumulated.statistic)), wt.blocks.map(b => pos(b.accumulated.threshold)),
      wt.blocks.map(b => b.alarm ? pos(b.accumulated.statistic) : null)]);
  const withBoard = wt.blocks.filter(b => b.board);
  if (!withBoard.length) return;
  plot('board', $('wt-board-plot'), {
    height: 160, scales: {x: {time: false}},
    axes: [{label: 't (s)'}, {label: 'g', size: 60}],
    series: [{}, {label: 'g', stroke: '#9467bd', width: 1.5, points: {show: true, size: 3}},
             {label: 'h', stroke: '#d62728', dash: [6, 4], width: 1, points: {show: false}}],
  }, [withBoard.map(b => b.t_s), withBoard.map(b => b.board.statistic), withBoard.map(b => b.board.threshold || null)]);
}

function draw() {
  if (wt.dirty && $('view-watch').classList.contains('active')) {
    wt.dirty = false;
    drawModePlots(); drawStatPlot();
    $('wt-stat').dataset.blocks = wt.blocks.length;
  }
  requestAnimationFrame(draw);
}

function redraw() { drawStatus(); drawCards(); wt.dirty = true; }

// ---- live --------------------------------------------------------------------------------------

function onWatch(w) {
  wt.events++;
  const fresh = !wt.watch || wt.watch.name !== w.name;
  if (fresh) wt.blocks = [];
  wt.watch = w;
  redraw();
}

function onBlock(b) {
  if (!wt.watch) return;
  const last = wt.blocks.length ? wt.blocks[wt.blocks.length - 1] : null;
  // A block already drawn (the snapshot and the live event crossed) is not added twice.
  if (last && b.block <= last.block) return;
  // One missed (the page subscribed after it went out): the whole run fetched again.
  if ((last ? last.block : 0) + 1 !== b.block) { refresh().catch(e => status(e.message, true)); return; }
  wt.blocks.push(b);
  if (wt.blocks.length > kKeptBlocks) wt.blocks.shift();
  redraw();
}

async function refresh() {
  const first = wt.watch === null;
  const s = await post('snapshot', {});
  wt.watch = s.watch; wt.blocks = s.blocks || [];
  if (first && wt.watch) showSettings(wt.watch.settings);
  redraw();
}

function listen() {
  if (!window.bench || !bench.live) { setTimeout(listen, 50); return; }
  bench.live.addEventListener('watch', e => onWatch(JSON.parse(e.data)));
  bench.live.addEventListener('watch-block', e => onBlock(JSON.parse(e.data)));
  bench.live.addEventListener('open', () => refresh().catch(e => status(e.message, true)));
}

async function download() {
  const j = await post('journal', {});
  const a = document.createElement('a');
  a.href = URL.createObjectURL(new Blob([j.text], {type: 'application/x-ndjson'}));
  a.download = j.name + '.jsonl';
  document.body.append(a); a.click(); a.remove();
  $('wt-download').dataset.lines = j.text.split('\n').filter(x => x).length;
  status('journal ' + j.name + '.jsonl: ' + $('wt-download').dataset.lines + ' lines (on disk: ' + j.path + ')');
}

function wire(id, action) {
  $(id).addEventListener('click', async () => { try { await action(); } catch (e) { status(e.message, true); } });
}
wire('wt-start', async () => {
  const r = await post('start', settings());
  // A step that succeeds clears the banner of an earlier failure (the board view's rule).
  if (typeof say === 'function') say('', false);
  // The run's own state may have come first (a run the board refused at once): it stays shown.
  if (!wt.watch || wt.watch.name !== r.name) status('started ' + r.name + ', journal ' + r.journal);
});
wire('wt-stop', async () => { await post('stop', {}); status('stopping: the journal keeps every block so far'); });
wire('wt-download', download);
document.querySelector('#tabs').addEventListener('click', () => { wt.dirty = true; });
refresh().then(() => { $('view-watch').dataset.ready = 'yes'; }).catch(e => status(e.message, true));
listen();
requestAnimationFrame(draw);
})();
