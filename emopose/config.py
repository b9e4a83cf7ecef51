"""Config plumbing that must exist before Hydra composes: the ${root:...} resolver."""

from __future__ import annotations

from pathlib import Path

from omegaconf import OmegaConf

PROJECT_ROOT = Path(__file__).resolve().parent.parent
CONFIG_DIR = PROJECT_ROOT / "conf"


def project_path(relative: str) -> str:
    """${root:library/g1} -> an absolute path inside the checkout, whatever the working directory."""
    path = Path(relative)
    return str(path if path.is_absolute() else PROJECT_ROOT / path)


def register_resolvers() -> None:
    if not OmegaConf.has_resolver("root"):
        OmegaConf.register_new_resolver("root", project_path)


register_resolvers()
