"""A stub of llama-cpp-python's server (`python -m llama_cpp.server`) on the fake OpenAI server.

What sets it apart, as the real server behaves: GET /v1/models lists the model owned_by "me" (the GGUF
path as its id); response_format may only be {"type": "text" | "json_object"} with an optional
"schema" inside (its grammar), and anything else (OpenAI's json_schema) is answered with HTTP 500
carrying pydantic's message, as its error handler wraps a failed request validation; every answer
carries `usage` with the prompt's token count.
"""

from __future__ import annotations

from fake_answers import Answer, http_error
from fake_openai import FakeOpenAI

MODEL_PATH = "/models/SmolLM2-135M-Instruct.Q4_1.gguf"
REFUSAL = ("[{'type': 'literal_error', 'loc': ('body', 'response_format', 'type'), "
           "'msg': \"Input should be 'text' or 'json_object'\", 'input': 'json_schema'}]")


def llama_cpp_formats(body: dict) -> Answer | None:
    """The 500 for a response_format llama-cpp-python's request model does not accept; None otherwise."""
    form = body.get("response_format")
    if form is None or (isinstance(form, dict) and form.get("type") in ("text", "json_object")):
        return None
    return http_error(500, REFUSAL)


def fake_llama_cpp(*args, **kwargs) -> FakeOpenAI:
    """A FakeOpenAI (same arguments) that answers as llama-cpp-python's server does."""
    server = FakeOpenAI(*args, **kwargs)
    server.gate = llama_cpp_formats
    server.listing = {"object": "list", "data": [{"id": MODEL_PATH, "object": "model", "owned_by": "me",
                                                  "permissions": []}]}
    return server
