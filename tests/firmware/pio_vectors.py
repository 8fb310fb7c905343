"""PlatformIO pre-build script for `pio test -e native`: generates the
protocol vectors header that tests/firmware/test_vectors includes, as the
Makefile does (platformio.ini: extra_scripts = pre:tests/firmware/pio_vectors.py)."""

import subprocess
from pathlib import Path

Import("env")  # noqa: F821 -- provided by PlatformIO's SCons

project = Path(env.subst("$PROJECT_DIR"))  # noqa: F821
generated = Path(env.subst("$BUILD_DIR")) / "generated"  # noqa: F821
subprocess.check_call([
    env.subst("$PYTHONEXE"),  # noqa: F821
    str(project / "tests" / "firmware" / "gen_vectors.py"),
    str(project / "protocol" / "vectors.json"),
    str(generated / "qs_vectors.h"),
])
env.Append(CPPPATH=[str(generated)])  # noqa: F821
