"""The robot's own voice at its microphone: an adaptive echo canceller and a double-talk gate that learns.

EchoCanceller: a partitioned-block frequency-domain NLMS filter (overlap-save, one 512-sample block per
VAD chunk, `partitions` blocks long: 8 x 32 ms = 256 ms covers the loudspeaker-to-microphone delay and a
room's early reflections). It predicts the echo from the reference (the samples the robot played) and
subtracts it; the VAD then hears the residual. Two filters (its class docstring) keep double talk from
teaching it to cancel the visitor while a changed echo path is still relearned.

EchoGate: whether a chunk's residual is louder than the robot's echo can be. The residual first loses
its projection on the echo estimate (a volume change scales the echo: that part is echo too). The floor
is the loudest reference RMS of the last `window_ms` times a coupling gain; the gain starts at the
classic Geigel assumption (echo at least `return_loss_db`, 6 dB, down) and falls to `margin_db` (10 dB)
above the residual coupling measured online: a decaying peak (`decay_db` per chunk) of residual RMS /
reference RMS over chunks where the robot talks alone, i.e. no louder than LEARN_DB over that peak
(a visitor's quiet onset teaches nothing; the peak can still rise LEARN_DB per chunk). It never rises
above the starting assumption, so a fresh gate behaves as the fixed Geigel gate did; once the canceller
has converged (a few seconds of the robot's speech, carried across replies: one EchoGate per microphone
and loudspeaker) the visitor is heard over loud syllables. Tested (tests/speech/test_vad_barge_in.py,
room echo of tests/speech/room.py): 0 self-triggers at -6, -12 and -20 dB and 6 dB louder again, the
floor at least 6 dB under the assumption once learned. In an offline simulation of 40 replies (not a
test) the floor ended 20-30 dB under it, with 0 self-triggers while the volume drifted +-2 dB and
stepped +6 dB once; an echo whose delay jumps by tens of ms between replies (a different room every
reply) self-triggered there before it was relearned.
"""

from __future__ import annotations

from collections import deque

import numpy as np

from emopose.speech.vad import CHUNK_S

ACTIVE_REFERENCE_RMS = 1e-3   # -60 dBFS: below this the robot is silent; nothing is learned from the chunk
LEARNED_DB = 6.0
SWITCH_DB = 3.0
LEARN_DB = 3.0
REGULARIZATION = 1e-6         # keeps bins the reference never excites from dividing by ~0


class EchoCanceller:
    """Two filters on one reference history (the two-path scheme): the background adapts on every block
    the robot plays, the foreground (whose residual is used) only on blocks where it talked alone, and
    takes the background's weights when they have cancelled clearly better (SWITCH_DB) of late. So an
    echo path that changes (the robot turned, the volume changed) is relearned, and double talk, which
    only ever disturbs the background, never teaches the foreground to cancel the visitor."""

    def __init__(self, block: int, partitions: int = 8, step: float = 0.5) -> None:
        if partitions < 1 or not 0.0 < step <= 1.0:
            raise ValueError(f"echo canceller: partitions must be >= 1 and step in (0, 1], "
                             f"got {partitions}, {step}")
        self.block, self.step = block, step
        bins = block + 1
        self.weights = np.zeros((2, partitions, bins), np.complex128)  # foreground, background
        self.spectra = np.zeros((partitions, bins), np.complex128)      # reference blocks, newest first
        self.power = np.zeros(bins)                                      # their smoothed power per bin
        self._previous = np.zeros(block)
        self._errors = np.zeros((2, bins), np.complex128)
        self._block_power = np.zeros(2)
        self._recent_power = np.zeros(2)  # both residuals' power, smoothed over a few blocks

    def cancel(self, mic: np.ndarray, reference: np.ndarray) -> np.ndarray:
        """One block of microphone and reference samples (floats) -> the residual (echo removed)."""
        self.spectra = np.roll(self.spectra, 1, axis=0)
        self.spectra[0] = np.fft.rfft(np.concatenate([self._previous, reference]))
        self._previous = reference
        echoes = np.fft.irfft((self.weights * self.spectra).sum(axis=1), axis=1)[:, self.block:]
        residuals = mic - echoes
        self._errors = np.fft.rfft(np.concatenate([np.zeros_like(residuals), residuals], axis=1), axis=1)
        self._block_power = np.mean(residuals * residuals, axis=1)
        return residuals[0]

    def learn(self, robot_alone: bool) -> None:
        """After a block the robot played: adapt the background, the foreground too if it talked alone."""
        energy = (np.abs(self.spectra) ** 2).sum(axis=0)
        self.power = 0.5 * self.power + 0.5 * energy
        normalised = self._errors / (self.power + REGULARIZATION * (1.0 + self.power.mean()))
        gradient = np.fft.irfft(np.conj(self.spectra) * normalised[:, None, :], axis=2)
        gradient[:, :, self.block:] = 0.0  # the constraint: a linear (not circular) correlation
        update = self.step * np.fft.rfft(gradient, axis=2)
        self.weights[1] += update[1]
        if robot_alone:
            self.weights[0] += update[0]
        self._recent_power = 0.7 * self._recent_power + 0.3 * self._block_power
        if self._recent_power[1] < self._recent_power[0] * 10 ** (-SWITCH_DB / 10):
            self.weights[0] = self.weights[1]
            self._recent_power[0] = self._recent_power[1]


class EchoGate:
    """Cancel the echo, say whether a residual can be the robot's, learn from chunks where it is alone."""

    def __init__(self, block: int, return_loss_db: float = 6.0, margin_db: float = 10.0,
                 window_ms: float = 256.0, decay_db: float = 0.3, partitions: int = 8) -> None:
        self.canceller = EchoCanceller(block, partitions)
        self.assumed_gain = 10 ** (-return_loss_db / 20)
        self.margin = 10 ** (margin_db / 20)
        self.decay = 10 ** (-decay_db / 20)
        self.coupling = self.assumed_gain   # the measured peak residual / reference ratio (starts safe)
        self._references: deque[float] = deque(maxlen=max(1, round(window_ms / 1000 / CHUNK_S)))
        self._residual_rms = 0.0

    @property
    def gain(self) -> float:
        """Residual louder than this times the recent reference level cannot be the robot's echo alone."""
        return min(self.assumed_gain, self.margin * self.coupling)

    @property
    def learned(self) -> bool:
        """The measured coupling puts the floor at least LEARNED_DB under the assumption: the canceller
        works in this room, so a visitor over the floor is no echo and a shorter onset window is safe."""
        return self.gain <= self.assumed_gain * 10 ** (-LEARNED_DB / 20)

    def residual(self, mic: np.ndarray, reference: np.ndarray) -> np.ndarray:
        self._references.append(rms(reference))
        out = self.canceller.cancel(mic, reference)
        # The part of the residual that is the echo estimate scaled (the loudspeaker's volume or distance
        # changed since the filter learned) is echo too: remove it, the visitor is not correlated with it.
        estimate = mic - out
        out = out - estimate * (np.dot(out, estimate) / (np.dot(estimate, estimate) + REGULARIZATION))
        self._residual_rms = rms(out)
        return out

    def above_floor(self) -> bool:
        return self._residual_rms > self.gain * max(self._references)

    def learn(self, double_talk: bool) -> None:
        """After each chunk: learn the echo path and its residual level unless the visitor may be talking."""
        if self._references[-1] < ACTIVE_REFERENCE_RMS:
            return
        ratio = self._residual_rms / max(self._references)
        # alone: no louder than the coupling seen so far allows (a visitor's quieter onset chunks, under
        # the floor's margin but over this, teach nothing); the peak may still rise LEARN_DB per chunk
        robot_alone = not double_talk and ratio <= min(self.gain, self.coupling * 10 ** (LEARN_DB / 20))
        self.canceller.learn(robot_alone)
        if robot_alone:
            self.coupling = max(self.coupling * self.decay, ratio)

    def forget_reference(self) -> None:
        """The robot started or stopped a reply: the echo floor restarts (the learned room stays)."""
        self._references.clear()
        self._references.append(0.0)


def rms(samples: np.ndarray) -> float:
    return float(np.sqrt(np.mean(samples * samples))) if len(samples) else 0.0
