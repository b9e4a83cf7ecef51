"""The FastAPI app factory: pages, static files, the API routers, the guard and JSON errors.

No interactive docs (Swagger/ReDoc load their scripts from a CDN, and nothing here may reach the
internet). Every error leaves as JSON {"error": ...} with a 4xx status saying what to fix; an
unexpected failure is logged here and answered with a short 500, never a traceback.
"""

from __future__ import annotations

import logging
from pathlib import Path

from fastapi import FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import FileResponse, JSONResponse
from fastapi.staticfiles import StaticFiles
from starlette.exceptions import HTTPException

from emopose.joint_limits import LibraryError
from emopose.web import api, studio_api, ws
from emopose.web.security import Guard
from emopose.web.session import LiveSession

log = logging.getLogger(__name__)
STATIC = Path(__file__).parent / "static"
NO_STORE = {"Cache-Control": "no-store"}  # pages change with the code; never serve a stale UI


def _problem(loc: tuple, message: str) -> str:
    where = ".".join(str(p) for p in loc if p != "body")
    return f"{where}: {message}" if where else message


def create_app(session: LiveSession) -> FastAPI:
    app = FastAPI(title="EmoPose", docs_url=None, redoc_url=None, openapi_url=None)
    app.state.session = session
    app.add_middleware(Guard, settings=session.settings)

    @app.exception_handler(RequestValidationError)
    async def invalid_request(request: Request, exc: RequestValidationError) -> JSONResponse:
        problems = [_problem(tuple(e.get("loc", ())), e.get("msg", "invalid")) for e in exc.errors()[:10]]
        return JSONResponse({"error": "invalid request: " + "; ".join(problems), "problems": problems},
                            status_code=422)

    @app.exception_handler(HTTPException)
    async def http_error(request: Request, exc: HTTPException) -> JSONResponse:
        return JSONResponse({"error": exc.detail}, status_code=exc.status_code, headers=exc.headers)

    @app.exception_handler(LibraryError)
    async def library_error(request: Request, exc: LibraryError) -> JSONResponse:
        return JSONResponse({"error": str(exc)}, status_code=422)

    @app.exception_handler(Exception)
    async def unexpected(request: Request, exc: Exception) -> JSONResponse:
        log.error("unhandled error on %s %s", request.method, request.url.path, exc_info=exc)
        return JSONResponse({"error": f"internal error ({type(exc).__name__}); see the server log"},
                            status_code=500)

    @app.get("/", include_in_schema=False)
    def chat_page() -> FileResponse:
        return FileResponse(STATIC / "index.html", headers=NO_STORE)

    @app.get("/studio", include_in_schema=False)
    def studio_page() -> FileResponse:
        return FileResponse(STATIC / "studio.html", headers=NO_STORE)

    app.include_router(api.router)
    app.include_router(studio_api.router)
    app.include_router(ws.router)
    app.mount("/static", StaticFiles(directory=STATIC), name="static")
    return app
