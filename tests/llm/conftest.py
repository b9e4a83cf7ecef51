"""The LLM client's tests: slow_servers is a helper module beside them, not a test module."""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
