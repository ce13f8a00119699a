"""Test-suite settings shared by every test module."""

import os

# The suite compiles the drivers it uses as it goes; a background compile of all
# the others (impactsym.warmup) would only compete with it for the two cores.
os.environ.setdefault("IMPACTSYM_BACKGROUND_COMPILE", "0")
# Many tests compare stderr exactly; on a cold numba cache the "compiling ..."
# notice would land in it. The notice is tested on its own (test_batch.py).
os.environ.setdefault("IMPACTSYM_COMPILE_NOTICE_AFTER", "inf")
