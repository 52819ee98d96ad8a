"""Puts the repository's tools/ on the import path, so that the tests in this folder import the
tools by name whatever the working directory (python3 -m unittest discover -s tests/tools)."""

import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
TOOLS = os.path.join(ROOT, "tools")
if TOOLS not in sys.path:
    sys.path.insert(0, TOOLS)
