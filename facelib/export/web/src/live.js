// Live mode of facelib's web player: a `facelib serve` session over WebSocket (docs/live.md).
// Each `frame` message carries the 52 ARKit weights of one frame, its time t_ms on the
// session clock and the speech audio of its own time span. The audio is scheduled on a Web
// Audio context, chunk after chunk; that context's clock decides which frame is shown, so the
// face follows the sound that is heard (session time = audioContext.currentTime - base).

const LEAD_S = 0.2; // audio is scheduled this far ahead of now: room for network jitter
const JOIN_S = 0.002; // a chunk this close to the end of the one before is played straight on
const AUDIBLE = 0.01; // |sample| above this counts as sound (16-bit PCM scaled to [-1, 1])

function pcmSamples(base64) {
  const text = atob(base64);
  const out = new Float32Array(text.length >> 1);
  for (let i = 0; i < out.length; i++) {
    const v = text.charCodeAt(2 * i) | (text.charCodeAt(2 * i + 1) << 8);
    out[i] = (v >= 32768 ? v - 65536 : v) / 32768;
  }
  return out;
}

// The morph-target meshes of an ARKit export (facelib export --targets arkit): the weights
// come in the order of its targets (facelib.export.arkit.arkit_names, case aside).
export function arkitMeshes(root) {
  const meshes = [];
  root.traverse((o) => { if (o.isMesh && o.morphTargetInfluences) meshes.push(o); });
  const names = meshes.length ? Object.keys(meshes[0].morphTargetDictionary) : [];
  if (names.length !== 52) {
    throw new Error(`the live page needs an ARKit head (52 morph targets, facelib export ` +
                    `--targets arkit --html DIR), this one has ${names.length}`);
  }
  return { meshes, names };
}

// A session's sound and frames: schedule() takes each frame message, at(t) gives the frame
// due at session time t (s), clock() the session time the listener hears now.
class Timeline {
  constructor(context) {
    this.context = context;
    this.base = null; // context time of session time 0
    this.next = 0; // context time where the last scheduled chunk ends
    this.frames = []; // [{t, weights, speaking, i}] not yet shown, in time order
    this.sounding = []; // [start, end] context times of scheduled chunks with sound
    this.reanchored = 0;
  }

  clock() { return this.base === null ? null : this.context.currentTime - this.base; }

  schedule(m) {
    const t = m.t_ms / 1000;
    const now = this.context.currentTime;
    if (this.base === null || this.base + t < now + 0.01) { // first, or late: start anew
      if (this.base !== null) this.reanchored += 1;
      this.base = now + LEAD_S - t;
    }
    let when = this.base + t;
    if (Math.abs(when - this.next) < JOIN_S) when = this.next;
    if (m.audio && m.audio.pcm) {
      const samples = pcmSamples(m.audio.pcm);
      if (samples.length) {
        const buffer = this.context.createBuffer(1, samples.length, m.audio.rate);
        buffer.copyToChannel(samples, 0);
        const source = this.context.createBufferSource();
        source.buffer = buffer;
        source.connect(this.context.destination);
        source.start(when);
        this.next = when + buffer.duration;
        if (samples.some((s) => Math.abs(s) > AUDIBLE)) this.sounding.push([when, this.next]);
      }
    }
    this.frames.push({ t: when - this.base, weights: m.arkit, speaking: m.speaking, i: m.i });
  }

  // the last frame due at session time t (older ones are dropped), or null
  at(t) {
    let due = null;
    while (this.frames.length && this.frames[0].t <= t) due = this.frames.shift();
    return due;
  }

  audible() {
    const now = this.context.currentTime;
    while (this.sounding.length && this.sounding[0][1] < now) this.sounding.shift();
    return this.sounding.some(([a, b]) => a <= now && now < b);
  }
}

// Connect to `url`, start a session and show its frames on `head` ({meshes, names}); `draw`
// renders. Returns the page's live API: say(text), close(), state().
export function connectLive(url, head, draw, { fps = 30, onStatus = () => {} } = {}) {
  const context = new AudioContext();
  const timeline = new Timeline(context);
  const ws = new WebSocket(url);
  const state = { connected: false, started: false, received: 0, shown: null, errors: [],
                  ended: false, drawn: 0 };
  const jaw = head.names.findIndex((n) => n.toLowerCase() === "jawopen");

  ws.onopen = () => {
    state.connected = true;
    ws.send(JSON.stringify({ type: "start", fps, outputs: ["arkit", "visemes"] }));
    onStatus("connected");
  };
  ws.onclose = () => { state.connected = false; onStatus("disconnected"); };
  ws.onerror = () => onStatus(`cannot connect to ${url}`);
  ws.onmessage = (event) => {
    const m = JSON.parse(event.data);
    if (m.type === "frame") { state.received += 1; timeline.schedule(m); }
    else if (m.type === "started") { state.started = true; onStatus("ready: type a line"); }
    else if (m.type === "error") { state.errors.push(m.message); onStatus(m.message); }
    else if (m.type === "end") state.ended = true;
  };

  const waiting = []; // capture() calls: [condition, resolve]
  function tick() {
    const frame = timeline.at(timeline.clock() ?? -Infinity);
    if (frame && frame.weights) {
      for (const mesh of head.meshes) {
        for (let k = 0; k < frame.weights.length; k++) mesh.morphTargetInfluences[k] = frame.weights[k];
      }
      state.shown = { i: frame.i, t: frame.t, speaking: frame.speaking,
                      jawOpen: jaw >= 0 ? frame.weights[jaw] : null };
    }
    draw();
    state.drawn += 1;
    const snapshot = live.state();
    for (let k = waiting.length - 1; k >= 0; k--) {
      if (waiting[k][0](snapshot)) { // the canvas holds exactly the frame in the snapshot
        waiting[k][1]({ state: snapshot, png: draw.canvas.toDataURL("image/png") });
        waiting.splice(k, 1);
      }
    }
    if (!state.closed) requestAnimationFrame(tick);
  }
  requestAnimationFrame(tick);

  const live = {
    async say(text) {
      await context.resume(); // the click that sends the line lets the page play sound
      ws.send(JSON.stringify({ type: "text", text, flush: true }));
    },
    close() { state.closed = true; ws.close(); context.close(); },
    state: () => ({ ...state, shown: state.shown && { ...state.shown }, clock: timeline.clock(),
                    audioTime: context.currentTime, audioState: context.state,
                    audible: timeline.audible(), reanchored: timeline.reanchored }),
    // resolves with the canvas as a PNG data URL and the state of the frame it shows, the
    // first time test(state) holds right after a frame is drawn
    capture: (test) => new Promise((resolve) => waiting.push([test, resolve])),
  };
  return live;
}
