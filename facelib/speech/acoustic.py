"""Visemes straight from the sound, in any language: the project's acoustic viseme model
(``facelib/data/visemes/acoustic_model.npz``, made by ``tools/train_viseme_model.py``).

Every 10 ms (frame ``i`` centred at ``5 + 10 i`` ms) a log-mel spectrum of a 25 ms window
is taken; a small network (a multilayer perceptron over the spectra of frames
``t + offsets``, ``offsets`` from about -200 ms to a few frames ahead) gives each frame's
probability of the 15 MPEG-4 visemes (0: silence), and a fixed-lag Viterbi pass over those
(a penalty per change of viseme) decides frame ``t`` once frame ``t + lag`` is heard. Frame
``t``'s viseme therefore depends on no sample later than ``look_ahead_ms`` after its centre:
the same code serves whole files (:func:`recognize_acoustic`) and streams
(:class:`AcousticStream`), with the same result. Each run of frames becomes one phone span
labelled with a representative IPA phone of its viseme (the model's ``labels``), so the
viseme chain (map, minimum durations, coarticulation, closures) treats it as it treats
aligned phones. numpy only.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from functools import cache
from pathlib import Path

import numpy as np

from facelib import data
from facelib.errors import DataError
from facelib.speech.audio import ALIGN_RATE, load_speech
from facelib.speech.timeline import PhoneTimeline, Span, append_span

__all__ = ["MODEL_FILE", "AcousticModel", "AcousticStream", "LevelState", "causal_normalize",
           "classes_to_spans", "frame_classes", "frame_log_probs", "load_model", "log_mel",
           "network_input", "recognize_acoustic", "start_level"]

MODEL_FILE = "visemes/acoustic_model.npz"
HOP = ALIGN_RATE // 100
"""Samples per 10 ms frame at 16 kHz."""
_FLOOR = 1e-8


@dataclass(frozen=True, eq=False)
class AcousticModel:
    """The network and its front end, as stored in the ``.npz``.

    mel: ``(n_mels, n_fft // 2 + 1) float32`` filterbank; n_fft: window length in samples
    (Hann, centred on the frame); mean, scale: ``(n_mels,)`` feature normalisation;
    offsets: ``(n_context,) int`` frame offsets stacked as the network's input (the last is
    the largest, ``>= 0``); weights, biases: per layer ``(n_in, n_out)`` and ``(n_out,)``
    float32 (ReLU between layers, softmax at the end); labels: ``(n_classes,)`` the IPA
    phone standing for each class (class k is viseme k, ``"SIL"`` for 0); lag: frames the
    Viterbi pass waits before deciding; switch_penalty: its cost (log probability) of a
    change of viseme; info: how it was made (JSON text); level_init: ``(n_mels,)`` the
    running mean spectrum :func:`causal_normalize` starts from, or None where the model
    takes the log-mel spectra as they are.
    """

    mel: np.ndarray
    n_fft: int
    mean: np.ndarray
    scale: np.ndarray
    offsets: np.ndarray
    weights: tuple[np.ndarray, ...]
    biases: tuple[np.ndarray, ...]
    labels: tuple[str, ...]
    lag: int
    switch_penalty: float
    info: str
    level_init: np.ndarray | None = None

    @property
    def look_ahead_ms(self) -> float:
        """How far past a frame's centre its decision looks (window half, context, lag)."""
        return 1000 * (self.n_fft / 2) / ALIGN_RATE + 10 * (int(self.offsets[-1]) + self.lag)

    @property
    def n_classes(self) -> int:
        return len(self.labels)


def model_from_arrays(arrays: dict[str, np.ndarray]) -> AcousticModel:
    """An :class:`AcousticModel` of the arrays of its ``.npz`` (KeyError if one lacks)."""
    n_layers = int(arrays["n_layers"])
    return AcousticModel(
        mel=np.asarray(arrays["mel"], np.float32), n_fft=int(arrays["n_fft"]),
        mean=np.asarray(arrays["mean"], np.float32),
        scale=np.asarray(arrays["scale"], np.float32),
        offsets=np.asarray(arrays["offsets"], np.int64),
        weights=tuple(np.asarray(arrays[f"w{k}"], np.float32) for k in range(n_layers)),
        biases=tuple(np.asarray(arrays[f"b{k}"], np.float32) for k in range(n_layers)),
        labels=tuple(str(x) for x in arrays["labels"]), lag=int(arrays["lag"]),
        switch_penalty=float(arrays["switch_penalty"]), info=str(arrays["info"]),
        level_init=(np.asarray(arrays["level_init"], np.float32) if "level_init" in arrays
                    else None))


@cache
def load_model(path: str | None = None) -> AcousticModel:
    """The shipped model (or the ``.npz`` at ``path``); DataError if it is unreadable."""
    where = str(data.path(MODEL_FILE)) if path is None else path
    try:
        with np.load(where, allow_pickle=False) as stored:
            model = model_from_arrays({k: stored[k] for k in stored.files})
    except (OSError, KeyError, ValueError) as exc:
        raise DataError(f"cannot read the acoustic viseme model: {exc}", path=where) from exc
    json.loads(model.info)  # the note of how it was made must be readable
    return model


def log_mel(samples: np.ndarray, model: AcousticModel, *, first: int = 0,
            n_frames: int | None = None) -> np.ndarray:
    """``(n_frames, n_mels) float32`` log-mel spectra (natural log of the power) of frames
    ``first ...`` of ``samples`` (``(n,)`` at 16 kHz); frame ``i`` is the Hann window of ``n_fft``
    samples centred at sample ``80 + 160 i``, zeros outside ``samples``. By default every
    frame whose centre lies inside ``samples``."""
    if n_frames is None:
        n_frames = max(-(-(samples.size - HOP // 2) // HOP) - first, 0)
    half = model.n_fft // 2
    start = first * HOP + HOP // 2 - half
    end = (first + n_frames - 1) * HOP + HOP // 2 + half
    lo, hi = max(start, 0), min(end, samples.size)
    chunk = np.zeros(max(end - start, 0), np.float32)
    if hi > lo:
        chunk[lo - start:hi - start] = samples[lo:hi]
    if n_frames <= 0:
        return np.zeros((0, model.mean.size), np.float32)
    frames = np.lib.stride_tricks.sliding_window_view(chunk, model.n_fft)[::HOP][:n_frames]
    window = np.hanning(model.n_fft + 1)[:-1].astype(np.float32)
    power = np.abs(np.fft.rfft(frames * window, axis=1)) ** 2
    return np.log(power.astype(np.float32) @ model.mel.T + _FLOOR).astype(np.float32)


def start_level(model: AcousticModel) -> LevelState:
    """The level state at the start of a recording."""
    init = model.level_init if model.level_init is not None else np.zeros(model.mean.size)
    return LevelState(None, np.asarray(init, np.float64))


def network_input(raw: np.ndarray, model: AcousticModel, state: LevelState
                  ) -> tuple[np.ndarray, LevelState]:
    """The network's per-frame input ``(n, n_mels) float32`` of log-mel frames ``raw``
    (:func:`log_mel`; level-normalised when the model says so, then standardised) and
    the level state after them."""
    if model.level_init is not None:
        raw, state = causal_normalize(raw, state)
    return ((raw - model.mean) / model.scale).astype(np.float32), state


@dataclass(frozen=True, slots=True)
class LevelState:
    """What :func:`causal_normalize` carries from frame to frame: ``peak``, the running
    peak of the frames' mean log power (None before the first frame), and ``mean``
    ``(n_mels,)``, the running mean spectrum of the loud frames."""

    peak: float | None
    mean: np.ndarray


CMN_RATE = 0.01
"""Weight of each loud frame in the running mean spectrum (a time constant of 1 s)."""
PEAK_DECAY = 0.02
"""How fast the running peak falls (natural log power per frame: 2 per second)."""
LOUD_BELOW_PEAK = 2.5
"""A frame is loud when its mean log power is within this of the running peak."""


def causal_normalize(raw: np.ndarray, state: LevelState) -> tuple[np.ndarray, LevelState]:
    """``raw`` log-mel frames ``(n, n_mels)`` minus the running mean spectrum of the loud
    frames up to each (level and channel taken out, causally), and the state after them."""
    out = np.empty_like(raw)
    peak, mean = state.peak, state.mean.astype(np.float64).copy()
    level = raw.mean(axis=1)
    for t in range(raw.shape[0]):
        peak = float(level[t]) if peak is None else max(float(level[t]), peak - PEAK_DECAY)
        if level[t] > peak - LOUD_BELOW_PEAK:
            mean += CMN_RATE * (raw[t] - mean)
        out[t] = raw[t] - mean
    return out, LevelState(peak, mean)


def _silence_feature(model: AcousticModel) -> np.ndarray:
    """``(n_mels,)``: the input of a frame of digital silence (padding beyond the audio;
    level-normalised against the starting mean spectrum)."""
    floor = np.log(np.full(model.mean.size, _FLOOR, np.float32))
    if model.level_init is not None:
        floor = floor - model.level_init
    return ((floor - model.mean) / model.scale).astype(np.float32)


def _network(stacked: np.ndarray, model: AcousticModel) -> np.ndarray:
    """``(n, n_classes)`` log probabilities of stacked inputs ``(n, n_context * n_mels)``."""
    x = stacked
    for k, (w, b) in enumerate(zip(model.weights, model.biases, strict=True)):
        x = x @ w + b
        if k < len(model.weights) - 1:
            np.maximum(x, 0, out=x)
    x = x - x.max(axis=1, keepdims=True)
    return x - np.log(np.exp(x).sum(axis=1, keepdims=True))


def frame_log_probs(features: np.ndarray, model: AcousticModel) -> np.ndarray:
    """``(n, n_classes)`` log probabilities of every frame of ``features`` ``(n, n_mels)``
    (:func:`network_input`; frames before the first and after the last count as digital
    silence)."""
    lo, hi = int(-model.offsets.min()), int(max(model.offsets.max(), 0))
    pad = _silence_feature(model)
    padded = np.concatenate([np.tile(pad, (lo, 1)), features, np.tile(pad, (hi, 1))])
    n = features.shape[0]
    stacked = np.concatenate([padded[lo + o:lo + o + n] for o in model.offsets], axis=1)
    return _network(stacked, model)


class AcousticStream:
    """Streaming recognition: :meth:`feed` samples (16 kHz) as they come, read the viseme
    class of each frame as soon as it is decided; :meth:`finish` decides the rest at the end.
    The classes are exactly those of :func:`frame_classes` of all the samples at once.
    Memory stays bounded: only the samples, spectra and back pointers later frames need."""

    def __init__(self, model: AcousticModel | None = None) -> None:
        self.model = load_model() if model is None else model
        m = self.model
        self._left = int(-min(int(m.offsets.min()), 0))
        self._right = int(max(int(m.offsets.max()), 0))
        self._pad = _silence_feature(m)
        self._samples = np.zeros(0, np.float32)  # stream samples from _sample0 (HOP multiple)
        self._sample0 = 0
        self._features = np.zeros((0, m.mean.size), np.float32)  # frames _feature0 ...
        self._feature0 = 0
        self._n_total: int | None = None  # frames in all, once finished
        self._level = start_level(m)
        self._n_scored = 0
        self._delta = np.zeros(m.n_classes)
        self._back: list[np.ndarray] = []  # back pointers of frames n_decided+1 ... n_scored-1
        self._n_decided = 0
        self.classes: list[int] = []
        """Every class decided so far, frame 0 first."""

    @property
    def n_samples(self) -> int:
        """Samples fed so far."""
        return self._sample0 + self._samples.size

    @property
    def _n_features(self) -> int:
        return self._feature0 + self._features.shape[0]

    def feed(self, samples: np.ndarray) -> list[int]:
        """Add ``samples`` ``(n,) float32``; the classes of the frames decided now."""
        if self._n_total is not None:
            raise DataError("this acoustic stream has finished")
        self._samples = np.concatenate([self._samples, np.asarray(samples, np.float32)])
        # frame i is complete once the samples up to 80 + 160 i + n_fft / 2 are in
        ready = (self.n_samples - HOP // 2 - self.model.n_fft // 2) // HOP + 1
        self._add_features(ready)
        return self._score(self._n_features - self._right)

    def finish(self) -> list[int]:
        """The audio has ended: the classes of every frame not yet decided."""
        n_total = max(-(-(self.n_samples - HOP // 2) // HOP), 0)
        self._add_features(n_total)
        self._n_total = n_total
        return self._score(n_total)

    def _add_features(self, ready: int) -> None:
        first = self._n_features
        if ready > first:
            raw = log_mel(self._samples, self.model, first=first - self._sample0 // HOP,
                          n_frames=ready - first)
            local, self._level = network_input(raw, self.model, self._level)
            self._features = np.concatenate([self._features, local])
        # the samples that later frames need start at 80 + 160 ready - n_fft / 2
        need = ready * HOP + HOP // 2 - self.model.n_fft // 2
        drop = (max(need, 0) - self._sample0) // HOP * HOP
        if drop > 0:
            self._samples = self._samples[drop:]
            self._sample0 += drop

    def _rows(self, frames: np.ndarray) -> np.ndarray:
        """``(len(frames), n_mels)`` spectra of frame indices ``frames`` (silence before the
        first frame and after the last)."""
        out = np.tile(self._pad, (frames.size, 1))
        inside = (frames >= 0) & (frames < self._n_features)
        out[inside] = self._features[frames[inside] - self._feature0]
        return out

    def _score(self, until: int) -> list[int]:
        """Viterbi over frames ``n_scored ... until - 1``; decide what the lag allows."""
        m = self.model
        out: list[int] = []
        if until > self._n_scored:
            frames = np.arange(self._n_scored, until)
            stacked = np.concatenate([self._rows(frames + o) for o in m.offsets], axis=1)
            steps = np.arange(m.n_classes)
            for row in _network(stacked, m):
                if self._n_scored == 0:
                    self._delta = row.astype(np.float64)
                else:
                    best = int(np.argmax(self._delta))
                    switch = self._delta[best] - m.switch_penalty
                    self._back.append(np.where(self._delta >= switch, steps, best))
                    self._delta = np.maximum(self._delta, switch) + row
                    self._delta -= self._delta.max()  # bounded over hours of audio
                self._n_scored += 1
                if self._n_scored - 1 - m.lag >= self._n_decided:  # frame t decided at t + lag
                    out.append(self._trace()[0])
                    self._decide(1)
            drop = self._n_scored - self._left - self._feature0
            if drop > 0:
                self._features = self._features[drop:]
                self._feature0 += drop
        if self._n_total is not None and self._n_scored > self._n_decided:
            rest = self._trace()
            out.extend(rest)
            self._decide(len(rest))
        self.classes.extend(out)
        return out

    def _trace(self) -> list[int]:
        """The best path's states of frames ``n_decided ... n_scored - 1``."""
        state = int(np.argmax(self._delta))
        path = [state]
        for back in reversed(self._back):
            state = int(back[state])
            path.append(state)
        return path[::-1]

    def _decide(self, n: int) -> None:
        """Frames ``n_decided ... n_decided + n - 1`` are decided (their pointers go)."""
        self._back = self._back[n:]
        self._n_decided += n


def frame_classes(samples: np.ndarray, model: AcousticModel | None = None) -> np.ndarray:
    """``(n_frames,) int`` viseme class of every 10 ms frame of ``samples`` (16 kHz)."""
    stream = AcousticStream(model)
    stream.feed(samples)
    stream.finish()
    return np.array(stream.classes, int)


def classes_to_spans(classes: np.ndarray | list[int], labels: tuple[str, ...],
                     duration_ms: int) -> tuple[Span, ...]:
    """Runs of equal frame classes as phone spans (frame i: ``[10 i, 10 i + 10)`` ms, the
    last clipped to ``duration_ms``), each labelled with its class's phone."""
    spans: list[Span] = []
    values = np.asarray(classes, int)
    if values.size == 0:
        return ()
    cuts = np.flatnonzero(np.diff(values)) + 1
    starts = np.concatenate([[0], cuts])
    ends = np.concatenate([cuts, [values.size]])
    for a, b in zip(starts, ends, strict=True):
        append_span(spans, labels[values[a]], int(10 * a), min(int(10 * b), duration_ms))
    return tuple(spans)


def recognize_acoustic(
    audio: str | Path | np.ndarray, *, sample_rate: int | None = None,
    model: AcousticModel | None = None,
) -> PhoneTimeline:
    """The viseme runs of speech ``audio`` (any language) as a phone timeline (IPA labels
    standing for their visemes, ``source="acoustic"``, no words). ``audio``: a sound file
    or an array with ``sample_rate``, as :func:`facelib.speech.audio.load_speech` reads."""
    model = load_model() if model is None else model
    samples = load_speech(audio, sample_rate=sample_rate)
    duration_ms = round(samples.size * 1000 / ALIGN_RATE)
    phones = classes_to_spans(frame_classes(samples, model), model.labels, duration_ms)
    return PhoneTimeline(phones, (), "acoustic", duration_ms, alphabet="ipa")
