"""Run pytest inside Blender: blender -b --factory-startup --python-exit-code 1
--python tests/blender/pytest_in_blender.py -- [pytest args]."""
import sys

import pytest

argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
sys.exit(pytest.main(["-p", "no:cacheprovider"] + argv))
