"""Write every frame of protocol/vectors.json as a seed file for the core's fuzzer, plus a few streams of them.

    python3 tests/fuzz/seeds.py OUT_DIR
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]


def main(out: Path) -> int:
    out.mkdir(parents=True, exist_ok=True)
    vectors = json.loads((REPO / "protocol" / "vectors.json").read_text())["vectors"]
    frames = [bytes.fromhex(v["frame"]) for v in vectors if v["direction"] == "to_firmware"]
    for i, frame in enumerate(frames):
        (out / f"vector-{i:03d}").write_bytes(frame)
    valid = [bytes.fromhex(v["frame"]) for v in vectors if v["direction"] == "to_firmware" and v["message"]]
    for k in range(8):  # streams of valid frames, several in a row, so the fuzzer starts from motion
        (out / f"stream-{k}").write_bytes(b"".join(valid[(k * 7 + j * 3) % len(valid)] for j in range(12)))
    print(f"{len(frames) + 8} seeds in {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main(Path(sys.argv[1])))
