"""Structured output: the forms in which a chat server may take the answer's JSON schema, and the order
in which check() offers them (planner.structured_output).

  json_schema         {"type": "json_schema", "json_schema": {"name", "strict", "schema"}}: OpenAI and
                      most hosted providers, llama.cpp's llama-server, Ollama, vLLM
  json_object_schema  {"type": "json_object", "schema": {...}}: llama-cpp-python's server, which takes
                      only "text" or "json_object" and answers json_schema with HTTP 500
  json_object         {"type": "json_object"}: any JSON, no schema (small models rarely match the contract)
  none                nothing: the prompt alone asks for JSON

`auto` starts from the form the identified server is known to take (emopose/llm/server.py; a hosted
model: what litellm reports for it; an unknown local server: json_schema) and goes down the list. A
form set by name falls back only to the later forms that still constrain the answer (never to none).
"""

from __future__ import annotations

FORMS = ("json_schema", "json_object_schema", "json_object", "none")
SETTINGS = ("auto", *FORMS)
SERVER_FORMS = {"llama-cpp-python": "json_object_schema", "llama-server": "json_schema",
                "ollama": "json_schema", "vllm": "json_schema", "openai-compatible": "json_schema"}


def response_format(form: str, schema: dict) -> dict | None:
    """litellm's response_format for `form` carrying `schema`."""
    if form == "json_schema":
        return {"type": "json_schema",
                "json_schema": {"name": "gesture_plan", "strict": True, "schema": schema}}
    if form == "json_object_schema":
        return {"type": "json_object", "schema": schema}
    if form == "json_object":
        return {"type": "json_object"}
    return None


def candidates(setting: str, server_kind: str, reported: str) -> list[str]:
    """The forms to probe, best first: `setting` (planner.structured_output) on a server of `server_kind`;
    `reported` is what litellm says the model takes (used for a hosted model or an unchecked server)."""
    if setting not in SETTINGS:
        raise ValueError(f"planner.structured_output = {setting!r}; choose one of {SETTINGS}")
    if setting == "auto":
        first = SERVER_FORMS.get(server_kind, reported)
        return [first, *(f for f in FORMS[FORMS.index(first) + 1:])]
    if setting == "none":
        return ["none"]
    return [f for f in FORMS[FORMS.index(setting):] if f != "none"]
