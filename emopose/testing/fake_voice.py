"""The fake robot's voice service (rt/api/voice/request|response) and its microphone stream.

Answers as the robot does (api ids and layouts in emopose/backends/g1/voice.py): 1003 start play takes
{"app_name", "stream_id"} and the PCM in `binary`; 1004 stop play {"app_name"}; 1005 answers
{"volume": v}; 1006 takes {"volume": 0-100}; 1010 takes {"R", "G", "B"} 0-255; 1001 TTS is accepted.
A malformed parameter answers 3204, an unknown api 3203, --fail-api API:CODE forces a code, and
--voice-mute takes requests without ever answering (a hung service).

Each chunk is logged with its arrival time (monotonic), stream, byte offset and PCM (base64), and the
robot's buffer is modelled: a new stream id cuts the old stream and starts sounding on arrival,
chunks of the same stream queue behind it; `ahead_s` is how much audio was still queued when the
chunk arrived (< 0: the robot ran dry, a stutter). A stop logs how much queued audio it cut.
--mic-wav streams a WAV (as 16 kHz mono) in 20 ms datagrams, paced in real time, to --mic-target
(the robot's group by default, or HOST:PORT), --mic-delay s after the robot is up.
"""

from __future__ import annotations

import argparse
import base64
import json
import socket
import threading
import time
from collections.abc import Callable

from emopose.backends.g1.api_types import Request_, Response_, ResponseHeader_, ResponseStatus_
from emopose.backends.g1.constants import (
    RPC_ERR_SERVER_API_NOT_IMPL,
    RPC_ERR_SERVER_API_PARAMETER,
    RPC_OK,
    request_topic,
    response_topic,
)
from emopose.backends.g1.dds import DdsSession
from emopose.backends.g1.voice import (
    PCM_BYTES_PER_SECOND,
    VOICE_API_GET_VOLUME,
    VOICE_API_SET_RGB_LED,
    VOICE_API_SET_VOLUME,
    VOICE_API_START_PLAY,
    VOICE_API_STOP_PLAY,
    VOICE_API_TTS,
    VOICE_SERVICE,
    checked_rgb,
    checked_volume,
    robot_pcm,
)
from emopose.execution.worker import Worker
from emopose.speech.g1_microphone import MIC_GROUP, MIC_PORT
from emopose.testing.fake_loco import answer_requests

MIC_DATAGRAM_S = 0.02


def add_voice_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--voice-service", default=VOICE_SERVICE)
    p.add_argument("--voice-mute", action="store_true", help="take voice requests, never answer them")
    p.add_argument("--mic-wav", default=None, help="stream this WAV as the robot's microphone")
    p.add_argument("--mic-target", default=f"{MIC_GROUP}:{MIC_PORT}", help="GROUP:PORT or HOST:PORT")
    p.add_argument("--mic-interface", default="127.0.0.1", help="our address multicast goes out on")
    p.add_argument("--mic-delay", type=float, default=0.5, help="seconds after READY before streaming")


def heard_at(rows: list[dict], stream_id: str, seconds: float) -> float | None:
    """When the modelled buffer sounds the audio `seconds` into stream `stream_id`, from the log's rows (its
    `t` is time.monotonic(), the clock of emopose.clock.MonotonicClock): a chunk starts sounding at its
    arrival plus the audio queued ahead of it (ahead_s; < 0: the robot ran dry and it sounds on arrival).
    None: that part of the stream never arrived, or a stop cut it before it sounded."""
    byte = 2 * int(seconds * PCM_BYTES_PER_SECOND / 2)
    stops = [r["t"] for r in rows if r["kind"] == "voice_stop" and r["stream_id"] == stream_id]
    for row in rows:
        if (row["kind"] == "voice_chunk" and row["stream_id"] == stream_id
                and row["offset"] <= byte < row["offset"] + row["bytes"]):
            sounds = row["t"] + max(row["ahead_s"], 0.0) + (byte - row["offset"]) / PCM_BYTES_PER_SECOND
            return None if stops and stops[0] <= sounds else sounds
    return None


class FakeVoice:
    def __init__(self, session: DdsSession, args: argparse.Namespace, log: Callable[[dict], None],
                 forced_codes: dict[int, int]) -> None:
        self._requests = session.reader(request_topic(args.voice_service), Request_)
        self._responses = session.writer(response_topic(args.voice_service), Response_)
        self.args, self._log, self._forced = args, log, forced_codes
        self.volume, self.rgb = 60, (0, 0, 0)
        self._streams: dict[str, tuple[str, int, float]] = {}  # app -> (stream id, bytes so far, buffer end)
        self.chunks = self.stops = 0
        self._workers = [Worker("fake-voice", self._serve, join_timeout_s=1.0)]
        if args.mic_wav:
            self._workers.append(Worker("fake-mic", self._stream_microphone, join_timeout_s=1.0))

    def start(self) -> None:
        for worker in self._workers:
            worker.start()

    def stop(self) -> None:
        for worker in self._workers:
            worker.stop()

    def summary(self) -> dict:
        return {"voice_chunks": self.chunks, "voice_stops": self.stops, "volume": self.volume,
                "rgb": self.rgb}

    def _serve(self, stop: threading.Event) -> None:
        answer_requests(self._requests, stop, lambda request: self._answer(request, time.monotonic()))

    def _answer(self, request: Request_, arrived: float) -> None:
        identity = request.header.identity
        api_id = int(identity.api_id)
        code, data = self._handle(api_id, request.parameter, bytes(request.binary), arrived)
        self._log({"kind": "voice", "t": arrived, "api_id": api_id, "parameter": request.parameter,
                   "code": code})
        if request.header.policy.noreply or self.args.voice_mute:
            return
        header = ResponseHeader_(identity=identity, status=ResponseStatus_(code=code))
        self._responses.write_typed(Response_(header=header, data=data, binary=[]))

    def _handle(self, api_id: int, parameter: str, binary: bytes, arrived: float) -> tuple[int, str]:
        if api_id in self._forced:
            return self._forced[api_id], ""
        try:
            p = json.loads(parameter) if parameter else {}
            if api_id == VOICE_API_START_PLAY:
                return self._play(str(p["app_name"]), str(p["stream_id"]), binary, arrived), ""
            if api_id == VOICE_API_STOP_PLAY:
                self._stop_play(str(p["app_name"]), arrived)
                return RPC_OK, ""
            if api_id == VOICE_API_GET_VOLUME:
                return RPC_OK, json.dumps({"volume": self.volume})
            if api_id == VOICE_API_SET_VOLUME:
                self.volume = checked_volume(p["volume"])
                return RPC_OK, ""
            if api_id == VOICE_API_SET_RGB_LED:
                self.rgb = checked_rgb((p["R"], p["G"], p["B"]))
                return RPC_OK, ""
            if api_id == VOICE_API_TTS:
                return RPC_OK, ""
        except (KeyError, TypeError, ValueError):
            return RPC_ERR_SERVER_API_PARAMETER, ""
        return RPC_ERR_SERVER_API_NOT_IMPL, ""

    def _play(self, app: str, stream_id: str, pcm: bytes, arrived: float) -> int:
        if not pcm or len(pcm) % 2:
            return RPC_ERR_SERVER_API_PARAMETER
        current, offset, buffer_end = self._streams.get(app, ("", 0, arrived))
        if current != stream_id:  # a new stream cuts the old one and sounds at once
            offset, buffer_end = 0, arrived
        ahead_s = buffer_end - arrived
        self._streams[app] = (stream_id, offset + len(pcm),
                              max(buffer_end, arrived) + len(pcm) / PCM_BYTES_PER_SECOND)
        self.chunks += 1
        self._log({"kind": "voice_chunk", "t": arrived, "app_name": app, "stream_id": stream_id,
                   "offset": offset, "bytes": len(pcm), "ahead_s": ahead_s,
                   "pcm": base64.b64encode(pcm).decode()})
        return RPC_OK

    def _stop_play(self, app: str, arrived: float) -> None:
        stream_id, _, buffer_end = self._streams.pop(app, ("", 0, arrived))
        self.stops += 1
        self._log({"kind": "voice_stop", "t": arrived, "app_name": app, "stream_id": stream_id,
                   "cut_s": max(0.0, buffer_end - arrived)})

    def _stream_microphone(self, stop: threading.Event) -> None:
        pcm = robot_pcm(self.args.mic_wav)
        host, port = self.args.mic_target.rsplit(":", 1)
        step = 2 * round(MIC_DATAGRAM_S * PCM_BYTES_PER_SECOND / 2)
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP) as sock:
            interface = socket.inet_aton(self.args.mic_interface)
            sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF, interface)
            sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)
            if stop.wait(self.args.mic_delay):
                return
            start = time.monotonic()
            self._log({"kind": "mic_start", "t": start, "bytes": len(pcm)})
            offsets = range(0, len(pcm), step)
            for k, first in enumerate(offsets):
                if stop.wait(max(0.0, start + k * MIC_DATAGRAM_S - time.monotonic())):
                    return
                sock.sendto(pcm[first:first + step], (host, int(port)))
            self._log({"kind": "mic_end", "t": time.monotonic(), "datagrams": len(offsets)})
