"""platformio.ini builds what the Makefile builds: the same sources, -D
defines, MCU, clock and the compiler and linker flags that change the code.
PlatformIO cannot run here (its packages come from its own registry), so
this test is what keeps the file users flash with honest."""

from __future__ import annotations

import configparser
import re
import shlex
import subprocess

import pytest

from avr_sim import REPO

# What PlatformIO's bare (framework-less) atmelavr build adds by itself
# (platform-atmelavr, builder/frameworks/_bare.py).
PIO_BARE_CFLAGS = {"-std=gnu11", "-Os", "-Wall", "-ffunction-sections", "-fdata-sections", "-flto",
                   "-fno-fat-lto-objects"}
PIO_BARE_LINKFLAGS = {"-Os", "-Wl,--gc-sections", "-flto", "-fuse-linker-plugin"}
NO_CODE_CHANGE = {"-g"}  # debug information only
BOARDS = {"uno": "UNO", "uno-laser": "UNO_LASER", "mega": "MEGA"}


def make_vars(*names: str) -> dict[str, list[str]]:
    """Variables of the top-level Makefile (and the files it includes), split into words."""
    rule = "qs-print-%: ; @echo '$*=$($*)'"
    out = subprocess.run(["make", "-C", str(REPO), "-s", "--no-print-directory", "--eval", rule,
                          *(f"qs-print-{n}" for n in names)], capture_output=True, text=True, check=True).stdout
    values = dict(line.split("=", 1) for line in out.splitlines() if "=" in line)
    return {n: values[n].split() for n in names}


def read_ini() -> configparser.RawConfigParser:
    ini = configparser.RawConfigParser(comment_prefixes=(";", "#"), inline_comment_prefixes=(";",))
    ini.optionxform = str  # type: ignore[assignment,method-assign]
    ini.read(REPO / "platformio.ini")
    return ini


def env_options(ini: configparser.RawConfigParser, section: str) -> dict[str, str]:
    """An environment's options with `extends` and ${section.option} resolved, as PlatformIO does."""
    options = dict(ini[section])
    if "extends" in options:
        base = env_options(ini, options.pop("extends").strip())
        options = {**base, **options}

    def expand(text: str) -> str:
        return re.sub(r"\$\{([^.}]+)\.([^}]+)\}", lambda m: expand(ini[m.group(1)][m.group(2)]), text)

    return {k: expand(v) for k, v in options.items()}


def flags(text: str) -> list[str]:
    """build_flags as single tokens: `-D NAME=V` becomes `-DNAME=V`, `-I dir` becomes `-Idir`."""
    words = shlex.split(text)
    out: list[str] = []
    i = 0
    while i < len(words):
        if words[i] in ("-D", "-I") and i + 1 < len(words):
            out.append(words[i] + words[i + 1])
            i += 2
        else:
            out.append(words[i])
            i += 1
    return out


def sources(options: dict[str, str], src_dir: str) -> set[str]:
    """The files build_src_filter selects under src_dir."""
    chosen: set[str] = set()
    for sign, pattern in re.findall(r"([+-])<([^>]+)>", options["build_src_filter"]):
        matched = {str(p.relative_to(REPO)) for p in (REPO / src_dir).glob(pattern)}
        chosen = chosen | matched if sign == "+" else chosen - matched
    return chosen


@pytest.fixture(scope="module")
def ini() -> configparser.RawConfigParser:
    return read_ini()


@pytest.mark.parametrize("env", sorted(BOARDS))
def test_board_env_matches_avr_mk(env: str, ini: configparser.RawConfigParser) -> None:
    key = BOARDS[env]
    mk = make_vars("AVR_SOURCES", "AVR_INCLUDES", "AVR_DEFINES", f"AVR_{key}_MCU", f"AVR_{key}_DEFINES",
                   "AVR_CFLAGS", "AVR_LDFLAGS")
    opts = env_options(ini, f"env:{env}")
    build = flags(opts["build_flags"])

    assert opts["platform"].strip() == "atmelavr"
    assert "framework" not in opts, "the firmware is bare avr-libc"
    assert opts["board_build.mcu"].strip() == mk[f"AVR_{key}_MCU"][0]
    assert sources(opts, ini["platformio"]["src_dir"].strip()) == set(mk["AVR_SOURCES"])

    defines = {f for f in build if f.startswith("-D")} | {f"-DF_CPU={opts['board_build.f_cpu'].strip()}"}
    assert defines == set(mk["AVR_DEFINES"] + mk[f"AVR_{key}_DEFINES"])
    assert {f for f in build if f.startswith("-I")} == set(mk["AVR_INCLUDES"])

    compile_flags = {f for f in build if not f.startswith(("-D", "-I", "-Wl,"))}
    assert set(mk["AVR_CFLAGS"]) - NO_CODE_CHANGE == PIO_BARE_CFLAGS | compile_flags
    assert set(mk["AVR_LDFLAGS"]) == PIO_BARE_LINKFLAGS | {f for f in build if f.startswith("-Wl,")}


def test_uno_and_mega_flash_through_their_bootloaders(ini: configparser.RawConfigParser) -> None:
    mega = env_options(ini, "env:mega")
    for env in ("env:uno", "env:uno-laser"):
        uno = env_options(ini, env)
        assert (uno["board"].strip(), uno["upload_protocol"].strip(), uno["upload_speed"].strip()) == \
            ("uno", "arduino", "115200")
    assert (mega["board"].strip(), mega["upload_protocol"].strip(), mega["upload_speed"].strip()) == \
        ("megaatmega2560", "wiring", "115200")


def test_native_env_matches_the_firmware_test_build(ini: configparser.RawConfigParser) -> None:
    mk = make_vars("NATIVE_CORE_SOURCES", "NATIVE_DEFINES", "FWT_CFLAGS")
    opts = env_options(ini, "env:native")
    build = flags(opts["build_flags"])

    assert opts["platform"].strip() == "native"
    assert opts["test_framework"].strip() == "unity"
    assert opts["test_build_src"].strip() == "yes"
    assert ini["platformio"]["test_dir"].strip() == "tests/firmware"
    assert sources(opts, ini["platformio"]["src_dir"].strip()) == set(mk["NATIVE_CORE_SOURCES"])
    test_defines = {f for f in mk["FWT_CFLAGS"] if f.startswith("-D")}
    assert set(mk["NATIVE_DEFINES"]) <= test_defines
    assert {f for f in build if f.startswith("-D")} == test_defines
    assert {f for f in build if f.startswith(("-std", "-W"))} == \
        {f for f in mk["FWT_CFLAGS"] if f.startswith(("-std", "-W"))}
    assert "-Ifirmware/core" in build
    # The vectors header the Makefile generates, PlatformIO generates with a script.
    scripts = [entry.split(":", 1)[-1] for entry in opts["extra_scripts"].split()]
    assert scripts and all((REPO / script).is_file() for script in scripts), scripts
