// The timeline editor: one lane per AU (and per FACS/emotion track), clips with
// onset / apex / offset handles, and a speech lane ({say, voice, start} tracks: drag
// to move; how long each lasts, and how its mouth moves, come from the server). The document it edits IS facsim's timeline format
// (facsim/data/timeline.schema.json): an envelope track when both ramps ease alike,
// two HapFACS segments when they differ. The server samples it for the preview.

const GUTTER = 150, RULER = 22, LANE = 28, PAD = 10, HANDLE = 6, MIN_RAMP = 0.05;
const round = (v, step = 0.01) => Math.round(v / step) * step;
const clamp = (v, lo, hi) => Math.min(hi, Math.max(lo, v));
const TIMING_KEYS = ['start', 'end', 'onset', 'apex', 'offset', 'intensity', 'easing', 'segments'];

/** The editable clip of a track ({start, onset, apex, offset, intensity, ein, eout}), a hold, or null. */
export function clipOf(track) {
  if (track.onset !== undefined) {
    const easing = track.easing || 'linear';
    return {start: track.start || 0, onset: track.onset, apex: track.apex, offset: track.offset,
            intensity: Number(track.intensity ?? 1), ein: easing, eout: easing};
  }
  const s = track.segments;
  if (s && s.length === 2 && !(s[0].from > 0) && Number(s[1].to) === 0 &&
      (s[1].from === undefined || Number(s[1].from) === Number(s[0].to))) {
    return {start: s[0].start, onset: s[0].end - s[0].start, apex: s[1].start - s[0].end,
            offset: s[1].end - s[1].start, intensity: Number(s[0].to),
            ein: s[0].easing || 'linear', eout: s[1].easing || 'linear'};
  }
  if (track.end !== undefined) return {hold: true, start: track.start || 0, end: track.end,
                                       intensity: Number(track.intensity ?? 1)};
  return null;
}

/** Write a clip back into ``track`` in facsim's format (keeps au/side/facs/emotion/table). */
export function writeClip(track, c) {
  for (const k of TIMING_KEYS) delete track[k];
  const r = v => Math.round(v * 1000) / 1000;
  if (c.hold) { Object.assign(track, {start: r(c.start), end: r(c.end), intensity: r(c.intensity)}); return track; }
  if (c.ein === c.eout) {
    Object.assign(track, {start: r(c.start), onset: r(c.onset), apex: r(c.apex), offset: r(c.offset),
                          intensity: r(c.intensity), easing: c.ein});
  } else {
    const top = c.start + c.onset + c.apex;
    track.segments = [
      {start: r(c.start), end: r(c.start + c.onset), from: 0, to: r(c.intensity), easing: c.ein},
      {start: r(top), end: r(top + c.offset), from: r(c.intensity), to: 0, easing: c.eout}];
  }
  return track;
}

/** Whether ``track`` is a speech track (text the face says). */
export const isSpeech = track => track.say !== undefined || track.audio !== undefined;
/** Seconds a speech clip lasts before the server has said (about 13 characters a second). */
const guessSpeech = track => Math.max(0.5, String(track.say || '').length / 13);

function trackEnd(track, spans) {
  if (isSpeech(track)) return (spans && spans.end) || (track.start || 0) + guessSpeech(track);
  const c = clipOf(track);
  if (c) return c.hold ? c.end : c.start + c.onset + c.apex + c.offset;
  return Math.max(0, ...(track.segments || []).map(s => s.end));
}

export class TimelineEditor {
  constructor(canvas, {units, onChange, onSeek, onSelect}) {
    this.canvas = canvas; this.units = units;
    this.onChange = onChange; this.onSeek = onSeek; this.onSelect = onSelect;
    this.doc = {duration: 3, fps: 30, intensities: 'hapfacs', tracks: []};
    this.time = 0; this.selected = -1; this.drag = null;
    this.shapes = null;   // each track's sampled level from the server (easings drawn exactly)
    this.speech = {};     // track index → {start, end, label} of each speech clip, from the server
    canvas.addEventListener('pointerdown', e => this.down(e));
    canvas.addEventListener('pointermove', e => this.move(e));
    canvas.addEventListener('pointerup', e => this.up(e));
    new ResizeObserver(() => this.draw()).observe(canvas);
  }

  get duration() { return this.doc.duration || Math.max(1, ...this.doc.tracks.map((t, i) => trackEnd(t, this.speech[i]))); }
  setDocument(doc) { this.doc = doc; this.speech = {}; this.selected = -1; this.onSelect(-1); this.changed(); }
  changed() { this.shapes = null; this.draw(); this.onChange(this.doc); }
  /** The server's sampled shapes for the document as it is now. */
  setShapes(shapes, speech = {}) { this.shapes = shapes; this.speech = speech; this.draw(); }

  lanes() {
    const lanes = new Map();
    this.doc.tracks.forEach((t, i) => {
      const speech = isSpeech(t);
      const key = speech ? 'speech' : t.au !== undefined ? `au:${t.au}` : `track:${i}`;
      if (!lanes.has(key)) {
        const unit = t.au !== undefined && this.units[t.au];
        const label = speech ? 'Speech' : t.au !== undefined ? `AU${t.au}${unit ? ' ' + unit.name : ''}`
          : t.emotion ? `emotion: ${t.emotion}` : `FACS: ${t.facs}`;
        lanes.set(key, {key, label, order: speech ? 5000 : t.au !== undefined ? t.au : 1000 + i, tracks: []});
      }
      lanes.get(key).tracks.push(i);
    });
    return [...lanes.values()].sort((a, b) => a.order - b.order);
  }

  x(t) { return GUTTER + t / this.duration * (this.width - GUTTER - PAD); }
  t(x) { return clamp((x - GUTTER) / (this.width - GUTTER - PAD) * this.duration, 0, this.duration); }

  draw() {
    const c = this.canvas, lanes = this.lanes();
    const dpr = window.devicePixelRatio || 1;
    this.width = c.clientWidth;
    const height = Math.max(130, RULER + lanes.length * LANE + PAD);
    c.style.height = height + 'px';
    c.width = this.width * dpr; c.height = height * dpr;
    const g = c.getContext('2d');
    g.setTransform(dpr, 0, 0, dpr, 0, 0);
    g.clearRect(0, 0, this.width, height);
    g.font = '12px system-ui, sans-serif';
    // ruler
    g.fillStyle = '#6d6a65'; g.strokeStyle = '#dedad3';
    const step = this.duration > 20 ? 5 : this.duration > 6 ? 1 : 0.5;
    for (let s = 0; s <= this.duration + 1e-9; s += step) {
      const x = this.x(s);
      g.beginPath(); g.moveTo(x, RULER - 6); g.lineTo(x, height); g.stroke();
      g.fillText(`${+s.toFixed(1)} s`, x + 2, 12);
    }
    if (!lanes.length) {
      g.fillStyle = '#8a8680';
      g.fillText('Empty timeline: make an expression with the sliders, then press “+ Add expression”.', GUTTER, RULER + 40);
    }
    this.hits = [];
    lanes.forEach((lane, li) => {
      const top = RULER + li * LANE;
      g.fillStyle = li % 2 ? '#f6f4f0' : '#fcfbf9';
      g.fillRect(0, top, this.width, LANE);
      g.fillStyle = '#2b2b2b';
      g.fillText(lane.label.length > 22 ? lane.label.slice(0, 21) + '…' : lane.label, 6, top + 18);
      for (const i of lane.tracks) this.drawTrack(g, i, top);
    });
    // playhead
    const px = this.x(this.time);
    g.strokeStyle = '#b3412f'; g.lineWidth = 2;
    g.beginPath(); g.moveTo(px, 0); g.lineTo(px, height); g.stroke(); g.lineWidth = 1;
  }

  /** A speech clip: a box from its start to its end, the mouth's movement inside, and its words. */
  drawSpeech(g, i, top) {
    const track = this.doc.tracks[i], bottom = top + LANE - 3, span = LANE - 8;
    const start = Number(track.start || 0), end = trackEnd(track, this.speech[i]);
    const x0 = this.x(start), x1 = this.x(end);
    g.fillStyle = i === this.selected ? 'rgba(143,95,47,0.30)' : 'rgba(143,95,47,0.14)';
    g.strokeStyle = '#8f5f2f';
    g.fillRect(x0, top + 3, x1 - x0, LANE - 6); g.strokeRect(x0, top + 3, x1 - x0, LANE - 6);
    const levels = this.shapes && !this.drag && this.shapes.levels[i];
    if (levels) {
      g.beginPath();
      const step = this.shapes.step;
      for (let k = Math.floor(start / step); k * step <= end && k < levels.length; k++) {
        const x = this.x(k * step), y = bottom - levels[k] * span;
        k * step <= start ? g.moveTo(x, y) : g.lineTo(x, y);
      }
      g.stroke();
    }
    g.save(); g.beginPath(); g.rect(x0, top, x1 - x0, LANE); g.clip();
    g.fillStyle = '#5a3a1a'; g.fillText(`“${track.say ?? track.transcript}”`, x0 + 4, top + 13);
    g.restore();
    this.hits.push({i, top, bottom, span, p: [start, start, end, end], clip: {hold: true, speech: true, start, end}});
  }

  drawTrack(g, i, top) {
    if (isSpeech(this.doc.tracks[i])) return this.drawSpeech(g, i, top);
    const track = this.doc.tracks[i], clip = clipOf(track), bottom = top + LANE - 3, span = LANE - 8;
    const y = level => bottom - level * span;
    const selected = i === this.selected;
    g.fillStyle = selected ? 'rgba(47,111,143,0.45)' : 'rgba(47,111,143,0.25)';
    g.strokeStyle = '#2f6f8f';
    let pts;
    if (clip && !clip.hold) {
      const p = [clip.start, clip.start + clip.onset, clip.start + clip.onset + clip.apex,
                 clip.start + clip.onset + clip.apex + clip.offset];
      pts = [[p[0], 0], [p[1], clip.intensity], [p[2], clip.intensity], [p[3], 0]];
      this.hits.push({i, top, bottom, span, p, clip});
    } else if (clip) {
      pts = [[clip.start, 0], [clip.start, clip.intensity], [clip.end, clip.intensity], [clip.end, 0]];
      this.hits.push({i, top, bottom, span, p: [clip.start, clip.start, clip.end, clip.end], clip});
    } else {
      pts = [];
      let level = 0;
      for (const s of track.segments || []) {
        const from = s.from !== undefined ? Number(s.from) : level;
        pts.push([s.start, from], [s.end, Number(s.to)]); level = Number(s.to);
      }
      if (pts.length) pts = [[pts[0][0], 0], ...pts, [pts[pts.length - 1][0], 0]];
    }
    if (!pts.length) return;
    const handles = pts;
    if (this.shapes && !this.drag && this.shapes.levels[i]) {   // the exact shape, easing included
      const step = this.shapes.step;
      const levels = this.shapes.levels[i];
      const first = Math.max(0, levels.findIndex(v => v > 0) - 1);
      const last = Math.min(levels.length - 1, levels.length - [...levels].reverse().findIndex(v => v > 0));
      if (first <= last) pts = levels.slice(first, last + 1).map((v, k) => [(first + k) * step, v]);
    }
    g.beginPath();
    pts.forEach(([t, v], k) => k ? g.lineTo(this.x(t), y(v)) : g.moveTo(this.x(t), y(v)));
    g.lineTo(this.x(pts[pts.length - 1][0]), y(0)); g.lineTo(this.x(pts[0][0]), y(0));
    g.closePath(); g.fill(); g.stroke();
    if (track.side && track.side !== 'both') {
      g.fillStyle = '#2f6f8f'; g.fillText(track.side === 'left' ? 'L' : track.side === 'right' ? 'R' : 'U',
                                         this.x(handles[0][0]) + 3, top + 12);
    }
    if (selected && clip && !clip.hold) {
      g.fillStyle = '#2f6f8f';
      for (const [t, v] of handles) { g.beginPath(); g.arc(this.x(t), y(v), 4.5, 0, 7); g.fill(); }
    }
  }

  pick(ex, ey) {
    for (const h of this.hits) {
      if (ey < h.top || ey > h.bottom + 3) continue;
      const xs = h.p.map(t => this.x(t));
      if (!h.clip.hold) {
        for (let k = 3; k >= 0; k--) if (Math.abs(ex - xs[k]) <= HANDLE) return {hit: h, handle: k};
        const plateau = h.bottom - h.clip.intensity * h.span;
        if (ex > xs[1] && ex < xs[2] && Math.abs(ey - plateau) <= 5) return {hit: h, handle: 'level'};
      }
      if (ex >= xs[0] && ex <= xs[3]) return {hit: h, handle: 'body'};
    }
    return null;
  }

  down(e) {
    const r = this.canvas.getBoundingClientRect(), ex = e.clientX - r.left, ey = e.clientY - r.top;
    const found = ey > RULER ? this.pick(ex, ey) : null;
    if (!found) { this.drag = {scrub: true}; this.seek(this.t(ex)); }
    else {
      this.select(found.hit.i);
      this.drag = {...found, t0: this.t(ex), clip0: {...found.hit.clip}};
    }
    this.canvas.setPointerCapture(e.pointerId);
  }

  move(e) {
    const r = this.canvas.getBoundingClientRect(), ex = e.clientX - r.left, ey = e.clientY - r.top;
    if (!this.drag) {
      const found = ey > RULER ? this.pick(ex, ey) : null;
      this.canvas.style.cursor = !found ? 'default' : found.handle === 'body' ? 'grab'
        : found.handle === 'level' ? 'ns-resize' : 'ew-resize';
      return;
    }
    if (this.drag.scrub) { this.seek(this.t(ex)); return; }
    const {hit, handle, clip0} = this.drag, c = {...clip0};
    const t = round(this.t(ex));
    const ends = [c.start, c.start + c.onset, c.start + c.onset + c.apex, c.start + c.onset + c.apex + c.offset];
    if (handle === 'body') {
      const shift = round(this.t(ex) - this.drag.t0);
      c.start = clamp(round(clip0.start + shift), 0, this.duration);
      if (c.hold) c.end = c.start + (clip0.end - clip0.start);
      if (c.speech) this.speech[hit.i] = {...this.speech[hit.i], start: c.start, end: c.end};
    } else if (handle === 'level') {
      c.intensity = clamp(round((hit.bottom - ey) / hit.span), 0, 1);
    } else if (c.hold) {
      if (handle < 2) c.start = Math.min(t, c.end - MIN_RAMP); else c.end = Math.max(t, c.start + MIN_RAMP);
    } else if (handle === 0) {
      c.start = clamp(t, 0, ends[1] - MIN_RAMP); c.onset = ends[1] - c.start;
    } else if (handle === 1) {
      const p1 = clamp(t, ends[0] + MIN_RAMP, ends[2]); c.onset = p1 - c.start; c.apex = ends[2] - p1;
    } else if (handle === 2) {
      const p2 = clamp(t, ends[1], ends[3] - MIN_RAMP); c.apex = p2 - ends[1]; c.offset = ends[3] - p2;
    } else if (handle === 3) {
      c.offset = Math.max(MIN_RAMP, t - ends[2]);
    }
    for (const k of ['start', 'onset', 'apex', 'offset', 'end']) if (c[k] !== undefined) c[k] = round(c[k]);
    if (c.speech) this.doc.tracks[hit.i].start = c.start;     // speech moves; its words set how long it lasts
    else writeClip(this.doc.tracks[hit.i], c);
    this.drag.moved = true;
    this.draw(); this.onSelect(hit.i);
  }

  up(e) {
    if (this.drag && this.drag.moved) this.changed();
    this.drag = null;
  }

  seek(t) { this.time = clamp(t, 0, this.duration); this.draw(); this.onSeek(this.time); }
  select(i) { this.selected = i; this.draw(); this.onSelect(i); }

  /** Add a track (facsim format) and select it; grows the duration to fit. */
  add(track) {
    this.doc.tracks.push(track);
    const end = trackEnd(track, null);
    if (end > (this.doc.duration || 0)) this.doc.duration = Math.ceil(end * 10) / 10;
    this.selected = this.doc.tracks.length - 1;
    this.onSelect(this.selected);
    this.changed();
  }

  remove(i) { this.doc.tracks.splice(i, 1); this.speech = {}; this.select(-1); this.changed(); }
}
