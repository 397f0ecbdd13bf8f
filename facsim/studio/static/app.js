// facsim studio page: sliders and a FACS string kept in sync, a live three.js face
// loaded from facsim's own .glb (every AU a morph target), characters, the timeline,
// exact server renders and export jobs. Tables come from the server's API, not from here.
import * as THREE from 'three';
import {GLTFLoader} from 'three/addons/loaders/GLTFLoader.js';
import {OrbitControls} from 'three/addons/controls/OrbitControls.js';
import {TimelineEditor, clipOf, isSpeech, writeClip} from '/static/timeline.js';

const $ = s => document.querySelector(s);
const el = (tag, attrs = {}, ...kids) => {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (k.startsWith('on')) e.addEventListener(k.slice(2), v);
    else if (k === 'class') e.className = v;
    else if (v !== undefined && v !== null && v !== false) e.setAttribute(k, v === true ? '' : v);
  }
  for (const k of kids) e.append(k);
  return e;
};
const debounce = (fn, ms) => { let t; return (...a) => { clearTimeout(t); t = setTimeout(() => fn(...a), ms); }; };
const pct = v => `${Math.round(v * 100)} %`;
const token = new URLSearchParams(location.search).get('token');

async function api(path, body, {raw = false} = {}) {
  const opts = {method: body === undefined ? 'GET' : 'POST', headers: {}};
  if (token) opts.headers['X-Facsim-Token'] = token;
  if (body !== undefined) { opts.headers['Content-Type'] = 'application/json'; opts.body = JSON.stringify(body); }
  const r = await fetch(path, opts);
  if (!r.ok) {
    let info; try { info = await r.json(); } catch { info = {error: `${r.status} ${r.statusText}`}; }
    const err = new Error(info.error || r.statusText); err.info = info; err.status = r.status; throw err;
  }
  return raw ? r : r.json();
}
function status(text) { $('#status').textContent = text; }
function showError(box, err) { box.hidden = !err; box.textContent = err ? (err.message || String(err)) : ''; }
function download(blob, name) {
  const a = el('a', {href: URL.createObjectURL(blob), download: name}); document.body.append(a); a.click(); a.remove();
}

const S = {
  catalogue: null, units: {}, levels: {}, intensities: 'hapfacs', character: null, emotion: null,
  mode: 'expression', curves: null, playing: false,
};
window.studio = S;   // for the tests and the curious

// ------------------------------------------------------------------ 3-D view
class Viewer {
  constructor(host) {
    this.host = host;
    this.renderer = new THREE.WebGLRenderer({antialias: true, preserveDrawingBuffer: true, alpha: true});
    this.renderer.setPixelRatio(window.devicePixelRatio || 1);
    this.renderer.outputColorSpace = THREE.SRGBColorSpace;
    host.append(this.renderer.domElement);
    this.scene = new THREE.Scene();
    this.camera = new THREE.PerspectiveCamera(20, 1, 0.01, 50);
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x8a7f74, 1.6));
    const key = new THREE.DirectionalLight(0xffffff, 2.2); key.position.set(0.6, 1.0, 1.4); this.scene.add(key);
    const fill = new THREE.DirectionalLight(0xdfe8ff, 0.7); fill.position.set(-1.2, 0.2, 0.8); this.scene.add(fill);
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.addEventListener('change', () => this.render());
    this.morphMeshes = []; this.rigid = {}; this.viewName = 'front';
    new ResizeObserver(() => this.resize()).observe(host);
  }
  resize() {
    const w = this.host.clientWidth, h = this.host.clientHeight;
    if (!w || !h) return;
    this.renderer.setSize(w, h, false); this.camera.aspect = w / h; this.camera.updateProjectionMatrix(); this.render();
  }
  load(buffer) {
    return new Promise((resolve, reject) => new GLTFLoader().parse(buffer, '', gltf => {
      if (this.root) this.scene.remove(this.root);
      this.root = gltf.scene; this.scene.add(this.root);
      this.morphMeshes = [];
      this.root.traverse(o => { if (o.morphTargetDictionary) this.morphMeshes.push(o); });
      this.bones = {};
      for (const name of ['head', 'eye_L', 'eye_R']) {
        const o = this.root.getObjectByName(name);
        if (o) this.bones[name] = {o, q: o.quaternion.clone(), p: o.position.clone()};
      }
      const box = new THREE.Box3().setFromObject(this.root);
      const size = box.getSize(new THREE.Vector3()), center = box.getCenter(new THREE.Vector3());
      const top = box.max.y, height = Math.min(size.y, 0.3);
      this.target = new THREE.Vector3(center.x, top - height * 0.5, center.z);
      this.distance = (height * 0.62) / Math.tan(THREE.MathUtils.degToRad(10));
      this.controls.target.copy(this.target);
      this.setView(this.viewName);
      resolve();
    }, reject));
  }
  setView(name, yaw, pitch) {
    const v = S.catalogue.views[name];
    this.viewName = name;
    yaw = THREE.MathUtils.degToRad(yaw ?? v.yaw); pitch = THREE.MathUtils.degToRad(pitch ?? v.pitch);
    if (!this.target) return;
    const d = this.distance;
    this.camera.position.set(this.target.x + d * Math.sin(yaw) * Math.cos(pitch), this.target.y + d * Math.sin(pitch),
                             this.target.z + d * Math.cos(yaw) * Math.cos(pitch));
    this.controls.update(); this.render();
  }
  /** The orbit camera's yaw and pitch in degrees (facsim's convention: + toward the character's left). */
  angles() {
    const o = this.camera.position.clone().sub(this.controls.target);
    return {yaw: THREE.MathUtils.radToDeg(Math.atan2(o.x, o.z)),
            pitch: THREE.MathUtils.radToDeg(Math.asin(o.y / o.length()))};
  }
  /** Show or hide the neck, shoulders and garment (the .glb's ``body`` node), as the Body choice says. */
  showBody(visible) {
    const body = this.root && this.root.getObjectByName('body');
    if (body) { body.visible = visible; this.render(); }
  }
  /** Show per-side AU levels {code: {left, right}}: morph weights, head and eye joints. */
  apply(levels) {
    for (const mesh of this.morphMeshes) {
      const dict = mesh.morphTargetDictionary, inf = mesh.morphTargetInfluences;
      inf.fill(0);
      for (const [code, lv] of Object.entries(levels)) {
        const base = 'AU' + String(code).padStart(2, '0');
        if (dict[base + '_L'] !== undefined) { inf[dict[base + '_L']] = lv.left; inf[dict[base + '_R']] = lv.right; }
        else if (dict[base] !== undefined) inf[dict[base]] = Math.max(lv.left, lv.right);
      }
    }
    const rigid = S.catalogue.rigid, level = c => levels[c] ? Math.max(levels[c].left, levels[c].right) : 0;
    const rot = new THREE.Vector3(), shift = new THREE.Vector3();
    for (const [code, m] of Object.entries(rigid.head)) {
      const l = level(code); if (!l) continue;
      if (m.translate) shift.add(new THREE.Vector3(...m.translate).multiplyScalar(l * 0.1));
      else rot.add(new THREE.Vector3(...m.axis).multiplyScalar(THREE.MathUtils.degToRad(m.degrees * l)));
    }
    const turn = (bone, v, dp) => {
      if (!bone) return;
      const angle = v.length(), q = new THREE.Quaternion();
      if (angle > 0) q.setFromAxisAngle(v.clone().normalize(), angle);
      bone.o.quaternion.copy(bone.q).multiply(q);
      bone.o.position.copy(bone.p).add(dp || new THREE.Vector3());
    };
    turn(this.bones.head, rot, shift);
    for (const [side, name] of [['left', 'eye_L'], ['right', 'eye_R']]) {
      const v = new THREE.Vector3();
      for (const [code, m] of Object.entries(rigid.eyes)) {
        const l = level(code); if (l) v.add(new THREE.Vector3(...m.axis).multiplyScalar(THREE.MathUtils.degToRad(m[side] * l)));
      }
      turn(this.bones[name], v);
    }
    this.render();
  }
  render() { if (this.target) this.renderer.render(this.scene, this.camera); }
}

// --------------------------------------------------------------- expression
function letterOf(v) {
  const t = S.catalogue.intensity_tables[S.intensities];
  return Object.keys(t).find(k => Math.abs(t[k] - v) < 5e-4);
}
function levelText(v) { const l = letterOf(v); return v <= 0 ? '0' : l && l !== 'E' ? `${l} · ${pct(v)}` : pct(v); }

function buildAuSliders() {
  const host = $('#au-groups');
  const titles = {'upper face': 'Upper face', 'lower face': 'Lower face', head: 'Head position', eyes: 'Eye position'};
  for (const region of S.catalogue.regions) {
    const group = el('details', {class: 'group', open: region !== 'eyes' && region !== 'head'}, el('summary', {}, titles[region]));
    for (const u of S.catalogue.units.filter(u => u.region === region)) {
      const slider = side => el('input', {type: 'range', min: 0, max: 1000, value: 0, id: `au-${u.code}${side ? '-' + side : ''}`,
        'aria-label': `AU${u.code} ${u.name}${side ? ' ' + side : ''}`, disabled: !u.simulated,
        oninput: e => setLevel(u.code, side, e.target.value / 1000)});
      const snaps = el('span', {class: 'snaps'}, ...['A', 'B', 'C', 'D', 'E'].map(L => el('button', {
        title: `${L}: ${pct(S.catalogue.intensity_tables[S.intensities][L])}`, disabled: !u.simulated,
        onclick: () => setLevel(u.code, null, S.catalogue.intensity_tables[S.intensities][L])}, L)));
      const row = el('div', {class: 'au', 'data-code': u.code, title: u.description + (u.simulated ? '' : ' (not simulated yet)')},
        el('div', {class: 'head'}, el('span', {class: 'code'}, `AU${u.code}`), el('span', {class: 'name'}, u.name),
           el('span', {class: 'value', id: `au-${u.code}-value`}, '0'),
           u.unilateral ? el('button', {class: 'lr', title: 'Set the left and right sides separately',
             onclick: e => { row.classList.toggle('split'); showSides(u.code); }}, 'L/R') : ''),
        el('div', {class: 'line both'}, slider(null), snaps));
      if (u.unilateral) {
        for (const side of ['left', 'right']) {
          row.append(el('div', {class: `line ${side}`, hidden: true}, el('span', {class: 'side-label'}, side[0].toUpperCase()), slider(side)));
        }
      }
      group.append(row);
    }
    host.append(group);
  }
}
function showSides(code) {
  const row = document.querySelector(`.au[data-code="${code}"]`), split = row.classList.contains('split');
  row.querySelector('.line.both').hidden = split;
  row.querySelectorAll('.line.left, .line.right').forEach(l => l.hidden = !split);
}
function syncSliders() {
  for (const u of S.catalogue.units) {
    const lv = S.levels[u.code] || {left: 0, right: 0};
    const row = document.querySelector(`.au[data-code="${u.code}"]`);
    if (u.unilateral && Math.abs(lv.left - lv.right) > 1e-6 && !row.classList.contains('split')) {
      row.classList.add('split'); showSides(u.code);
    }
    $(`#au-${u.code}`).value = Math.round(Math.max(lv.left, lv.right) * 1000);
    if (u.unilateral) { $(`#au-${u.code}-left`).value = Math.round(lv.left * 1000); $(`#au-${u.code}-right`).value = Math.round(lv.right * 1000); }
    const same = Math.abs(lv.left - lv.right) < 1e-6;
    $(`#au-${u.code}-value`).textContent = same ? levelText(lv.left) : `L ${pct(lv.left)} · R ${pct(lv.right)}`;
    row.classList.toggle('on', lv.left > 0 || lv.right > 0);
  }
}
function setLevel(code, side, value) {
  const lv = S.levels[code] || {left: 0, right: 0};
  if (side) lv[side] = value; else { lv.left = value; lv.right = value; }
  if (lv.left || lv.right) S.levels[code] = lv; else delete S.levels[code];
  S.emotion = null;
  showExpression(); syncSliders(); updateFacsFromSliders();
}
function showMode(text, timeline) { const m = $('#mode'); m.textContent = text; m.classList.toggle('timeline', timeline); }
function showExpression() { S.mode = 'expression'; stop(); viewer.apply(S.levels); showMode('showing the sliders', false); }
const updateFacsFromSliders = debounce(async () => {
  const levels = Object.fromEntries(Object.entries(S.levels));
  try {
    const r = await api('/api/expression', {levels, intensities: S.intensities});
    $('#facs').value = r.expression; facsError(null);
  } catch (err) { facsError(err); }
}, 120);
function setFromUnits(units) {
  S.levels = {};
  for (const u of units) { (S.levels[u.code] ||= {left: 0, right: 0})[u.side] = u.level; }
  syncSliders(); showExpression();
}
function facsError(err) {
  const box = $('#facs-error'), input = $('#facs');
  input.classList.toggle('bad', !!err);
  if (!err) { box.hidden = true; return; }
  box.hidden = false; box.textContent = err.message;
  const pos = err.info && err.info.position;
  if (pos !== undefined && pos !== null) {
    const text = input.value, len = Math.max(1, (err.info.token || '').length);
    const caret = el('span', {class: 'caret'}, text.slice(0, pos), el('mark', {}, text.slice(pos, pos + len) || ' '), text.slice(pos + len));
    box.prepend(caret);
    box.dataset.position = pos;
  }
}
const parseFacs = debounce(async () => {
  try {
    const r = await api('/api/parse', {expression: $('#facs').value, intensities: S.intensities});
    facsError(null); S.emotion = null; setFromUnits(r.units);
  } catch (err) { facsError(err); }
}, 200);

async function applyEmotion() {
  if (!S.emotion) return;
  const body = {name: S.emotion, table: $('#emotion-table').value, intensity: $('#emotion-intensity').value / 100,
                intensities: S.intensities};
  if ($('#blend-with').value) { body.blend_with = $('#blend-with').value; body.weight = $('#blend-weight').value / 100; }
  try {
    const r = await api('/api/emotion', body);
    $('#facs').value = r.expression; facsError(null); setFromUnits(r.units);
    document.querySelectorAll('#emotions button').forEach(b => b.classList.toggle('active', b.dataset.emotion === S.emotion));
  } catch (err) { facsError(err); }
}

// --------------------------------------------------------------- characters
const BODY = [['gender', 'Gender', 0, 1, 0.01, 'female … male'], ['age', 'Age', 1, 90, 1, 'years'],
              ['african', 'African', 0, 1, 0.01], ['asian', 'Asian', 0, 1, 0.01], ['caucasian', 'Caucasian', 0, 1, 0.01],
              ['muscle', 'Muscle', 0, 1, 0.01], ['weight', 'Weight', 0, 1, 0.01]];
let characterList;
function buildCharacterControls() {
  const grid = $('#presets');
  const names = Object.keys(characterList.presets);
  for (const name of names) {
    grid.append(el('button', {'data-character': name, title: characterList.presets[name].description,
                              onclick: () => chooseCharacter(characterList.presets[name])},
                   el('img', {alt: '', 'data-src': `/api/characters/${name}/thumbnail.png`}), name));
  }
  loadThumbnails();
  for (const [key, label, min, max, step, hint] of BODY) {
    $('#character-sliders').append(el('label', {class: 'slider'}, el('span', {}, label, hint ? el('br') : '', hint ? el('small', {}, hint) : ''),
      el('input', {type: 'range', id: `ch-${key}`, min, max, step, oninput: e => { S.character[key] = +e.target.value; characterEdited(); }}),
      el('output', {id: `ch-${key}-out`})));
  }
  for (const name of characterList.sliders) {
    $('#shape-sliders').append(el('label', {class: 'slider', 'data-slider': name}, el('span', {title: name}, name.split('/')[1]),
      el('input', {type: 'range', min: -1, max: 1, step: 0.05, value: 0, 'data-name': name,
                   oninput: e => { S.character.face[name] = +e.target.value; if (!+e.target.value) delete S.character.face[name]; characterEdited(); }}),
      el('output')));
  }
  $('#shape-filter').addEventListener('input', e => {
    const q = e.target.value.toLowerCase();
    document.querySelectorAll('#shape-sliders .slider').forEach(s => s.hidden = q && !s.dataset.slider.includes(q));
  });
}
async function loadThumbnails() {
  // one at a time: the first visit renders them in the worker, which also serves the Render button
  for (const img of document.querySelectorAll('#presets img')) {
    for (let attempt = 0; attempt < 4; attempt++) {
      const ok = await new Promise(res => { img.onload = () => res(true); img.onerror = () => res(false); img.src = img.dataset.src + (attempt ? `?retry=${attempt}` : ''); });
      if (ok) break;
      await new Promise(res => setTimeout(res, 1500));
    }
  }
}
function syncCharacterControls() {
  const c = S.character;
  for (const [key] of BODY) { $(`#ch-${key}`).value = c[key]; $(`#ch-${key}-out`).textContent = key === 'age' ? Math.round(c[key]) : (+c[key]).toFixed(2); }
  document.querySelectorAll('#shape-sliders input').forEach(i => {
    const v = c.face[i.dataset.name] || 0; i.value = v; i.nextSibling.textContent = v ? v.toFixed(2) : '';
  });
  document.querySelectorAll('#presets button').forEach(b => b.classList.toggle('active', b.dataset.character === c.name));
}
function characterEdited() { S.character.name = ''; S.character.description = ''; syncCharacterControls(); reloadCharacter(); }
const reloadCharacter = debounce(() => loadCharacter(), 600);
async function chooseCharacter(params) { S.character = structuredClone(params); syncCharacterControls(); await loadCharacter(); }
let loadSerial = 0;
async function loadCharacter() {
  const serial = ++loadSerial;
  $('#loading').hidden = false; showError($('#character-error'), null);
  try {
    const r = await api('/api/character/glb', {character: S.character}, {raw: true});
    const buffer = await r.arrayBuffer();
    if (serial !== loadSerial) return;
    await viewer.load(buffer);
    viewer.showBody($('#body').value !== 'none');
    viewer.apply(S.mode === 'timeline' && S.curves ? timelineLevels(editor.time) : S.levels);
    status(`${S.character.name || 'custom character'} · ready`);
  } catch (err) { showError($('#character-error'), err); status(err.message); }
  finally { if (serial === loadSerial) $('#loading').hidden = true; }
}

// ----------------------------------------------------------------- timeline
let editor;
function timelineLevels(t) {
  const c = S.curves; if (!c) return {};
  const i = Math.min(c.frames - 1, Math.max(0, Math.round(t * c.fps)));
  const out = {};
  for (const [code, sides] of Object.entries(c.curves)) out[code] = {left: sides.left ? sides.left[i] : 0, right: sides.right ? sides.right[i] : 0};
  return out;
}
function showTime(t) {
  $('#clock').textContent = `${t.toFixed(2)} s`;
  if (S.curves) { S.mode = 'timeline'; viewer.apply(timelineLevels(t)); showMode(`showing the timeline at ${t.toFixed(2)} s`, true); }
}
let previewSerial = 0;
function timelineChanged(doc) { refreshPreview(doc, ++previewSerial); }
const refreshPreview = debounce(async (doc, serial) => {
  $('#duration').value = doc.duration; $('#fps').value = doc.fps;
  try {
    const preview = await api('/api/timeline/preview', {timeline: doc});
    if (serial !== previewSerial) return;          // the document changed meanwhile
    const longest = Math.max(0, ...Object.values(preview.speech).map(s => s.end));
    if (doc.duration && longest > doc.duration + 1e-3) {     // grow the clip so the speech is not cut off
      doc.duration = Math.ceil(longest * 10) / 10; editor.changed(); return;
    }
    S.curves = preview; editor.setShapes(preview.shapes, preview.speech);
    loadSpeechAudio(doc, serial, Object.keys(preview.speech).length > 0);
    showError($('#timeline-error'), null);
    if (S.mode === 'timeline') showTime(editor.time);
  } catch (err) { showError($('#timeline-error'), err); }
}, 120);
/** The timeline's speech as WAV from the server, so Play sounds like the exported video. */
async function loadSpeechAudio(doc, serial, speaks) {
  if (S.audio) { S.audio.pause(); URL.revokeObjectURL(S.audio.src); S.audio = null; }
  if (!speaks) return;
  try {
    const r = await api('/api/timeline/audio', {timeline: doc}, {raw: true});
    if (serial === previewSerial && r.status === 200) S.audio = new Audio(URL.createObjectURL(await r.blob()));
  } catch (err) { showError($('#timeline-error'), err); }
}
function inspector(i) {
  const box = $('#clip-inspector');
  box.replaceChildren(); box.hidden = i < 0;
  if (i < 0) return;
  const track = editor.doc.tracks[i], clip = clipOf(track);
  if (isSpeech(track)) return speechInspector(box, i, track);
  const what = track.au !== undefined ? `AU${track.au} ${S.units[track.au]?.name || ''}` : track.emotion || track.facs;
  box.append(el('strong', {}, what));
  const update = () => { writeClip(track, clip); editor.changed(); inspector(i); };
  if (track.au !== undefined && S.units[track.au]?.unilateral) {
    box.append(el('label', {}, 'Side ', el('select', {onchange: e => { track.side = e.target.value; editor.changed(); }},
      ...['both', 'left', 'right'].map(s => el('option', {selected: (track.side || 'both') === s}, s)))));
  }
  if (clip && !clip.hold) {
    for (const k of ['start', 'onset', 'apex', 'offset']) {
      box.append(el('label', {}, `${k} `, el('input', {type: 'number', min: k === 'onset' || k === 'offset' ? 0.05 : 0, step: 0.1, value: +clip[k].toFixed(3),
        'data-field': k, onchange: e => { clip[k] = Math.max(+e.target.min, +e.target.value); update(); }}), ' s'));
    }
    box.append(el('label', {}, 'intensity ', el('input', {type: 'number', min: 0, max: 1, step: 0.05, value: clip.intensity, 'data-field': 'intensity',
      onchange: e => { clip.intensity = Math.min(1, Math.max(0, +e.target.value)); update(); }})));
    box.append(el('span', {class: 'snaps'}, ...['A', 'B', 'C', 'D', 'E'].map(L => el('button', {onclick: () => { clip.intensity = S.catalogue.intensity_tables[S.intensities][L]; update(); }}, L))));
    for (const [k, label] of [['ein', 'easing in'], ['eout', 'easing out']]) {
      box.append(el('label', {}, `${label} `, el('select', {'data-field': k, onchange: e => { clip[k] = e.target.value; update(); }},
        ...S.catalogue.easings.map(n => el('option', {selected: clip[k] === n}, n)))));
    }
  } else if (clip) {
    box.append(el('span', {}, `hold ${clip.start}–${clip.end} s at ${pct(clip.intensity)}`));
  } else box.append(el('span', {}, 'segments (edit the file to change them)'));
  box.append(el('button', {onclick: () => editor.remove(i)}, 'Delete clip'));
}
function speechInspector(box, i, track) {
  const changed = () => editor.changed();
  box.append(el('strong', {}, 'Speech'));
  if (track.say === undefined) box.append(el('span', {}, `a recording (${track.audio}): edit the file to change it`));
  else {
    box.append(el('label', {class: 'grow'}, 'says ', el('input', {type: 'text', value: track.say, 'data-field': 'say', style: 'flex:1',
      onchange: e => { track.say = e.target.value; changed(); }})));
    box.append(el('label', {}, 'voice ', el('select', {'data-field': 'voice', onchange: e => { track.voice = e.target.value; changed(); }},
      ...S.catalogue.voices.map(v => el('option', {selected: (track.voice || 'slt') === v}, v)))));
  }
  box.append(el('label', {}, 'start ', el('input', {type: 'number', min: 0, step: 0.1, value: +(track.start || 0), 'data-field': 'start',
    onchange: e => { track.start = Math.max(0, +e.target.value); changed(); }}), ' s'));
  const span = editor.speech[i];
  if (span) box.append(el('span', {class: 'hint'}, `${(span.end - span.start).toFixed(2)} s of speech`));
  box.append(el('button', {onclick: () => editor.remove(i)}, 'Delete clip'));
}
function addSpeechClip() {
  const text = $('#say-text').value.trim();
  if (!text) { showError($('#timeline-error'), new Error('Type the text the face should say first.')); return; }
  showError($('#timeline-error'), null);
  const start = editor.time >= editor.duration - 0.05 ? 0 : +editor.time.toFixed(2);
  editor.add({say: text, voice: $('#say-voice').value, start});
}
function addExpressionClips() {
  const start = editor.time >= editor.duration - 0.05 ? 0 : +editor.time.toFixed(2);
  const entries = Object.entries(S.levels);
  if (!entries.length) { showError($('#timeline-error'), new Error('The face is neutral: move some sliders (or pick an emotion) first.')); return; }
  showError($('#timeline-error'), null);
  for (const [code, lv] of entries) {
    const unit = S.units[code];
    const sides = Math.abs(lv.left - lv.right) < 1e-6 || !unit.unilateral ? [['both', Math.max(lv.left, lv.right)]] : [['left', lv.left], ['right', lv.right]];
    for (const [side, level] of sides) if (level > 0) {
      const track = {au: +code}; if (side !== 'both') track.side = side;
      editor.add(writeClip(track, {start, onset: 1, apex: 1, offset: 1, intensity: level, ein: 'linear', eout: 'linear'}));
    }
  }
}
let playStart = null;
function play() {
  if (S.playing) return stop();
  if (!S.curves) return;
  S.playing = true; $('#play').textContent = '❚❚ Pause';
  if (editor.time >= editor.duration - 1e-3) editor.time = 0;
  const t0 = performance.now() - editor.time * 1000;
  if (S.audio) { S.audio.currentTime = editor.time; S.audio.play().catch(() => {}); }
  const tick = now => {
    if (!S.playing) return;
    const t = (now - t0) / 1000;
    if (t >= editor.duration) { editor.seek(editor.duration); stop(); return; }
    editor.seek(t); requestAnimationFrame(tick);
  };
  requestAnimationFrame(tick);
}
function stop() { S.playing = false; $('#play').textContent = '▶ Play'; if (S.audio) S.audio.pause(); }

// ------------------------------------------------------------------ outputs
function renderOptions() {
  const view = $('#view').value, o = {size: +$('#size').value, background: $('#background').value,
    antialias: $('#antialias').value === 'fxaa' ? 'fxaa' : +$('#antialias').value, body: $('#body').value};
  if (view === 'orbit') { const a = viewer.angles(); o.view = 'front'; o.yaw = +a.yaw.toFixed(1); o.pitch = +a.pitch.toFixed(1); }
  else o.view = view;
  return o;
}
async function render() {
  const button = $('#render'); button.disabled = true; button.textContent = 'Rendering…';
  const body = {expression: $('#facs').value, character: S.character, engine: $('#engine').value,
                intensities: S.intensities, options: renderOptions()};
  const t0 = performance.now();
  try {
    const r = await api('/api/render', body, {raw: true});
    const blob = await r.blob();
    $('#render-image').src = URL.createObjectURL(blob);
    $('#render-figure').hidden = false;
    const o = body.options;
    $('#render-caption').replaceChildren(`${r.headers.get('X-Facsim-Expression')} · ${S.character.name || 'custom'} · ${body.engine} · ${o.size} px · ${((performance.now() - t0) / 1000).toFixed(1)} s `,
      el('a', {href: $('#render-image').src, download: 'face.png'}, 'download PNG'));
  } catch (err) { $('#render-figure').hidden = false; $('#render-caption').textContent = err.message; }
  finally { button.disabled = false; button.textContent = 'Render'; }
}
const EXPORT_NAMES = {png: 'PNG image', video: 'video', glb: '3-D model', 'arkit-csv': 'ARKit CSV', facs: '.facs notation'};
async function startExport(kind, format) {
  const body = {kind, format, timeline: editor.doc, character: S.character, engine: $('#engine').value,
                expression: $('#facs').value, intensities: S.intensities, options: renderOptions()};
  if (kind === 'video' && body.options.size % 2) body.options.size += 1;
  const label = kind === 'video' ? format.toUpperCase() + ' video' : EXPORT_NAMES[kind];
  const bar = el('progress', {max: 1, value: 0}), state = el('span', {class: 'state'}, 'queued');
  const cancel = el('button', {}, 'Cancel');
  const item = el('li', {'data-kind': kind}, el('div', {class: 'job-line'}, el('strong', {}, label), state, cancel), bar);
  $('#jobs').prepend(item);
  if (kind !== 'png' && !editor.doc.tracks.length) { state.textContent = 'the timeline is empty: add a clip first'; cancel.remove(); bar.remove(); return; }
  let job;
  try { job = await api('/api/jobs', body); } catch (err) { state.textContent = err.message; cancel.remove(); return; }
  item.dataset.job = job.id;
  cancel.onclick = () => api(`/api/jobs/${job.id}/cancel`, {});
  const events = new EventSource(`/api/jobs/${job.id}/events`);
  const finish = (text, link) => { events.close(); cancel.remove(); state.replaceChildren(text, link || ''); item.dataset.state = text; };
  events.addEventListener('progress', e => {
    const j = JSON.parse(e.data); bar.max = j.total || 1; bar.value = j.done;
    state.textContent = j.state === 'queued' ? 'waiting…' : !j.total ? 'starting…'
      : kind === 'video' ? `frame ${j.done} of ${j.total}` : 'working…';
    item.dataset.progress = (+item.dataset.progress || 0) + 1;
  });
  events.addEventListener('done', e => {
    const j = JSON.parse(e.data); bar.value = bar.max;
    finish('done · ', el('a', {href: j.download, download: j.filename, class: 'download'}, `download ${j.filename}`));
  });
  events.addEventListener('failed', e => finish(`failed: ${JSON.parse(e.data).error}`));
  events.addEventListener('cancelled', () => finish('cancelled'));
  events.onerror = () => { if (events.readyState === EventSource.CLOSED) finish('connection lost'); };
}

// ------------------------------------------------------------------ analyse
/** Send a photo or video to the camera processor; a photo's FACS code goes into the sliders, a video's
 *  timeline into the editor. Progress and cancel go through the job machinery like the exports. */
async function analyseFile(file) {
  const state = $('#analyse-state'), bar = $('#analyse-progress'), cancel = $('#analyse-cancel'), box = $('#analyse-error');
  showError(box, null); state.textContent = `uploading ${file.name}…`; bar.hidden = false; bar.value = 0; bar.max = 1;
  const done = text => { state.textContent = text; bar.hidden = true; cancel.hidden = true; };
  let job;
  try {
    const headers = {'Content-Type': file.type || 'application/octet-stream'};
    if (token) headers['X-Facsim-Token'] = token;
    const r = await fetch('/api/analyse', {method: 'POST', headers, body: file});
    job = await r.json();
    if (!r.ok) throw new Error(job.error || r.statusText);
  } catch (err) { done(''); showError(box, err); return; }
  cancel.hidden = false; cancel.onclick = () => api(`/api/jobs/${job.id}/cancel`, {});
  const events = new EventSource(`/api/jobs/${job.id}/events`);
  events.addEventListener('progress', e => {
    const j = JSON.parse(e.data); bar.max = j.total || 1; bar.value = j.done;
    state.textContent = j.state === 'queued' ? 'waiting…' : j.total > 1 ? `frame ${j.done} of ${j.total}` : 'looking for a face…';
  });
  events.addEventListener('done', async e => {
    events.close();
    try {
      const result = await api(JSON.parse(e.data).download);
      if (result.kind === 'video') {
        editor.setDocument(result.timeline); editor.seek(0);
        done(`${file.name}: a face in ${result.found} of ${result.frames} frames → the timeline`);
      } else {
        $('#facs').value = result.expression; S.emotion = null;
        const r = await api('/api/parse', {expression: result.expression, intensities: S.intensities});
        facsError(null); setFromUnits(r.units);
        done(`${file.name}: ${result.expression}`);
      }
    } catch (err) { done(''); showError(box, err); }
  });
  events.addEventListener('failed', e => { events.close(); done(''); showError(box, new Error(JSON.parse(e.data).error)); });
  events.addEventListener('cancelled', () => { events.close(); done('cancelled'); });
  events.onerror = () => { if (events.readyState === EventSource.CLOSED) done('connection lost'); };
}

// ------------------------------------------------------------------- start
let viewer;
async function main() {
  status('loading…');
  const [catalogue, emotions, characters] = await Promise.all([api('/api/catalogue'), api('/api/emotions'), api('/api/characters')]);
  S.catalogue = catalogue; characterList = characters;
  for (const u of catalogue.units) S.units[u.code] = u;
  viewer = new Viewer($('#viewer')); S.viewer = viewer;
  buildAuSliders();
  // views
  for (const name of Object.keys(catalogue.views)) {
    const label = name.replace(/-/g, ' ');
    $('#views').append(el('button', {onclick: () => { viewer.setView(name); $('#view').value = name; }}, label));
    $('#view').append(el('option', {value: name}, label));
  }
  $('#view').append(el('option', {value: 'orbit'}, 'as in the 3-D view'));
  // what is under the head (facsim/data/body.yaml's garments, or none)
  for (const name of catalogue.bodies) $('#body').append(el('option', {value: name}, name));
  $('#body').value = catalogue.default_body;
  $('#body').addEventListener('change', e => viewer.showBody(e.target.value !== 'none'));
  // emotions
  for (const [name, t] of Object.entries(emotions.tables)) $('#emotion-table').append(el('option', {value: name, title: t.source}, t.title.length > 28 ? name : t.title));
  for (const name of emotions.names) {
    $('#emotions').append(el('button', {'data-emotion': name, onclick: () => { S.emotion = name; applyEmotion(); }}, name));
    $('#blend-with').append(el('option', {value: name}, name));
  }
  for (const id of ['emotion-intensity', 'blend-weight']) $(`#${id}`).addEventListener('input', e => { $(`#${id}-out`).textContent = `${e.target.value} %`; applyEmotion(); });
  $('#emotion-table').addEventListener('change', applyEmotion);
  $('#blend-with').addEventListener('change', applyEmotion);
  $('#intensities').addEventListener('change', e => { S.intensities = e.target.value; parseFacs(); });
  $('#facs').addEventListener('input', parseFacs);
  $('#reset').addEventListener('click', () => { $('#facs').value = '0'; S.emotion = null; setFromUnits([]); facsError(null);
    document.querySelectorAll('#emotions button').forEach(b => b.classList.remove('active')); });
  document.querySelectorAll('.tabs button').forEach(b => b.addEventListener('click', () => {
    document.querySelectorAll('.tabs button, .tab').forEach(x => x.classList.remove('active'));
    b.classList.add('active'); $(`#tab-${b.dataset.tab}`).classList.add('active');
  }));
  // characters
  buildCharacterControls();
  $('#random').addEventListener('click', async () => {
    try { const r = await api('/api/character', {random: +$('#seed').value}); chooseCharacter(r.character); }
    catch (err) { showError($('#character-error'), err); }
  });
  $('#character-save').addEventListener('click', async () => {
    try { const r = await api('/api/character/yaml', {character: S.character}, {raw: true}); download(await r.blob(), `${S.character.name.replace(/[^\w-]+/g, '-') || 'character'}.yaml`); }
    catch (err) { showError($('#character-error'), err); }
  });
  $('#character-load').addEventListener('change', async e => {
    const file = e.target.files[0]; if (!file) return;
    try { const r = await api('/api/character/load', {text: await file.text()}); chooseCharacter(r.character); }
    catch (err) { showError($('#character-error'), err); }
    e.target.value = '';
  });
  // timeline
  editor = new TimelineEditor($('#timeline-canvas'), {units: S.units, onChange: timelineChanged, onSeek: showTime, onSelect: inspector});
  S.editor = editor;
  for (const u of catalogue.units.filter(u => u.simulated)) $('#add-au').append(el('option', {value: u.code}, `AU${u.code} ${u.name}`));
  $('#add-au').value = 12;
  $('#add-au-clip').addEventListener('click', () => {
    const start = editor.time >= editor.duration - 0.05 ? 0 : +editor.time.toFixed(2);
    editor.add(writeClip({au: +$('#add-au').value}, {start, onset: 1, apex: 1, offset: 1, intensity: 1, ein: 'linear', eout: 'linear'}));
  });
  $('#add-expression').addEventListener('click', addExpressionClips);
  for (const v of catalogue.voices) $('#say-voice').append(el('option', {value: v}, v));
  $('#add-speech').addEventListener('click', addSpeechClip);
  $('#analyse-file').addEventListener('change', e => { const file = e.target.files[0]; if (file) analyseFile(file); e.target.value = ''; });
  $('#play').addEventListener('click', play);
  $('#duration').addEventListener('change', e => { editor.doc.duration = Math.max(0.1, +e.target.value); editor.changed(); });
  $('#fps').addEventListener('change', e => { editor.doc.fps = Math.max(1, +e.target.value); editor.changed(); });
  $('#timeline-clear').addEventListener('click', () => editor.setDocument({duration: 3, fps: 30, intensities: S.intensities, tracks: []}));
  for (const fmt of ['yaml', 'json']) $(`#timeline-save-${fmt}`).addEventListener('click', async () => {
    try { const r = await api('/api/timeline/save', {timeline: editor.doc, format: fmt}, {raw: true}); download(await r.blob(), `timeline.${fmt}`); }
    catch (err) { showError($('#timeline-error'), err); }
  });
  $('#timeline-load').addEventListener('change', async e => {
    const file = e.target.files[0]; if (!file) return;
    try { const r = await api('/api/timeline/load', {name: file.name, text: await file.text()}); editor.setDocument(r.timeline); }
    catch (err) { showError($('#timeline-error'), err); }
    e.target.value = '';
  });
  document.addEventListener('keydown', e => { if (e.code === 'Space' && !/INPUT|SELECT|TEXTAREA|BUTTON/.test(e.target.tagName)) { e.preventDefault(); play(); } });
  // outputs
  $('#render').addEventListener('click', render);
  document.querySelectorAll('[data-export]').forEach(b => b.addEventListener('click', () => startExport(b.dataset.export, b.dataset.format)));
  editor.setDocument({duration: 3, fps: 30, intensities: 'hapfacs', tracks: []});
  await chooseCharacter(characters.presets.ava || Object.values(characters.presets)[0]);
  S.ready = true;
}
main().catch(err => { status(`could not start: ${err.message}`); console.error(err); });
