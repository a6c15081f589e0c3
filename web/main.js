// shadowlab's page: the form, the automation contract (docs/web.md) and the pictures. The work
// runs in Rust (pkg/shadowlab_web.js, built by `make web`); `run` is a JSPI export, so it
// returns a promise while the GPU's waits suspend inside it.
import init, { open, run, picture, catalogue, lose_device } from './pkg/shadowlab_web.js';

const $ = (id) => document.getElementById(id);
let catalog = { techniques: [], scenes: [] };
let busy = false;
let adapterLabel = '';

// wgpu names a browser adapter by its description, which browsers may leave empty: then the
// page asks WebGPU itself for what it tells (vendor, architecture).
async function describeAdapter(fromRust) {
  if (!fromRust.startsWith(' (')) return fromRust;
  try {
    const a = await navigator.gpu.requestAdapter({ powerPreference: 'high-performance' });
    const i = (a && a.info) || {};
    const words = [i.vendor, i.architecture, i.device, i.description].filter(Boolean).join(' ');
    const fallback = i.isFallbackAdapter ? ', fallback adapter' : '';
    return `${words || 'unnamed adapter'} (WebGPU${fallback})`;
  } catch (e) {
    return `unnamed adapter${fromRust}`;
  }
}

function status(text, error) {
  $('status').textContent = text;
  $('status').className = error ? 'error' : '';
}

function fillLights(scene, selected) {
  const s = catalog.scenes.find((x) => x.name === scene);
  $('light').innerHTML = '';
  for (let i = 0; i < (s ? s.lights : 1); i++) {
    $('light').add(new Option(`light ${i}`, String(i), false, String(i) === String(selected)));
  }
}

// A request from the query string of the contract: scene=NAME&t=SPEC&t=SPEC&size=WxH&light=K
function requestFrom(params) {
  const size = (params.get('size') || '256x256').split('x').map(Number);
  return {
    scene: params.get('scene') || 'courtyard',
    light: Number(params.get('light') || 0),
    width: size[0] || 0,
    height: size[1] || 0,
    techniques: params.getAll('t'),
  };
}

function requestFromForm() {
  const params = new URLSearchParams();
  params.set('scene', $('scene').value);
  params.set('light', $('light').value);
  params.set('size', $('size').value.trim());
  for (const line of $('specs').value.split('\n')) {
    if (line.trim()) params.append('t', line.trim());
  }
  return params;
}

function showForm(req) {
  $('scene').value = req.scene;
  fillLights(req.scene, req.light);
  $('size').value = `${req.width}x${req.height}`;
  $('specs').value = req.techniques.join('\n');
}

function canvasOf(rgba, w, h) {
  const c = document.createElement('canvas');
  c.width = w;
  c.height = h;
  if (rgba.length === 4 * w * h) {
    c.getContext('2d').putImageData(new ImageData(new Uint8ClampedArray(rgba), w, h), 0, 0);
  }
  return c;
}

function showOutcome(out) {
  const body = $('table').tBodies[0];
  body.innerHTML = '';
  $('time-head').textContent = `ms (${out.timer})`;
  const fmt = (x, d) => (x == null ? 'n/a' : Number(x).toFixed(d));
  for (const t of out.techniques) {
    const row = body.insertRow();
    for (const v of [t.label, fmt(t.wrong_pct, 3), fmt(t.false_lit_pct, 3), fmt(t.false_shadow_pct, 3), fmt(t.mae, 4),
      String(t.shadow_bytes), fmt(t.total_ms, 1)]) {
      row.insertCell().textContent = v;
    }
  }
  $('table').hidden = false;
  const pics = $('pictures');
  pics.innerHTML = '';
  out.techniques.forEach((t, i) => {
    for (const which of ['shaded', 'error']) {
      const fig = document.createElement('figure');
      fig.appendChild(canvasOf(picture(i, which), out.width, out.height));
      const cap = document.createElement('figcaption');
      cap.textContent = which === 'error' ? `${t.label}: wrong pixels against rt in red` : `${t.label}: shaded`;
      fig.appendChild(cap);
      pics.appendChild(fig);
    }
  });
}

// One run: the page's result, its title (the contract's signal) and the table.
async function go(params) {
  if (busy) return { error: 'a run is in progress' };
  busy = true;
  $('run').disabled = true;
  const req = requestFrom(params);
  showForm(req);
  document.title = 'shadowlab: running';
  status(`Running ${req.techniques.join(', ') || '(nothing)'} on ${req.scene} at ${req.width}x${req.height}...`);
  let out;
  try {
    out = JSON.parse(await run(JSON.stringify(req)));
    if (out.lost) {
      // the device was lost (a GPU reset, a frozen tab): open a new one and run again, once
      status(`${out.error}: opening the GPU again...`);
      adapterLabel = await describeAdapter(await open());
      out = JSON.parse(await run(JSON.stringify(req)));
      if (!out.error) out.recovered = true;
    }
    if (out.adapter !== undefined) out.adapter = adapterLabel;
  } catch (e) {
    // a panic in Rust: its message (globalThis.shadowlabPanic) says more than the trap
    out = { error: `the run failed: ${globalThis.shadowlabPanic || e}` };
  }
  $('shadowlab-result').textContent = JSON.stringify(out);
  if (out.error) {
    document.title = `shadowlab: error: ${out.error}`;
    status(out.error, true);
  } else {
    document.title = 'shadowlab: done';
    status(`Done: ${out.evaluated_pixels} evaluated pixels.`);
    showOutcome(out);
  }
  busy = false;
  $('run').disabled = false;
  return out;
}

async function main() {
  await init();
  catalog = JSON.parse(catalogue());
  for (const s of catalog.scenes) $('scene').add(new Option(s.name, s.name));
  $('scene').onchange = () => fillLights($('scene').value, 0);
  $('pick').onchange = () => {
    if ($('pick').value) $('specs').value = `${$('specs').value.trim()}\n${$('pick').value}`.trim();
    $('pick').value = '';
  };
  $('form').onsubmit = (e) => {
    e.preventDefault();
    go(requestFromForm());
  };
  // for drivers: window.shadowlab.run('scene=courtyard&t=sm&size=256x256') resolves to the result
  // and window.shadowlab.loseDevice() destroys the device, as a GPU reset would (for tests)
  window.shadowlab = { run: (query) => go(new URLSearchParams(query)), loseDevice: () => lose_device() };
  const params = new URLSearchParams(location.search);
  showForm(requestFrom(params.has('scene') ? params : new URLSearchParams('scene=courtyard&t=sm&t=csm&t=lt')));
  try {
    if (!navigator.gpu) throw new Error('this browser has no WebGPU (navigator.gpu)');
    if (typeof WebAssembly.Suspending !== 'function') {
      throw new Error('this browser lacks WebAssembly JS Promise Integration (JSPI: Chromium 137+, Firefox 153+)');
    }
    adapterLabel = await describeAdapter(await open());
    $('adapter').textContent = `GPU: ${adapterLabel}`;
    // the registry again, now with what this device cannot run (and why)
    catalog = JSON.parse(catalogue());
    for (const t of catalog.techniques) {
      const o = new Option(`${t.name} (${t.lights.join(', ')})`, t.name);
      if (t.unavailable) {
        o.textContent = `${t.name}: unavailable, ${t.unavailable.replace(/^'[^']*' is unavailable on this device: /, '')}`;
        o.disabled = true;
      }
      $('pick').add(o);
    }
  } catch (e) {
    $('adapter').textContent = '';
    document.title = `shadowlab: error: ${e.message || e}`;
    status(`${e.message || e}`, true);
    return;
  }
  $('run').disabled = false;
  if (params.get('run') === '1') await go(params);
}

main();
