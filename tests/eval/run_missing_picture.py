"""steadyxr-eval refuses a picture it cannot load: exit 2, a message naming the picture, nothing written.

    python3 run_missing_picture.py STEADYXR_EVAL OUT_DIR
"""
import os
import shutil
import subprocess
import sys

exe, out = sys.argv[1], sys.argv[2]
shutil.rmtree(out, ignore_errors=True)
env = dict(os.environ)
env["ASAN_OPTIONS"] = (env.get("ASAN_OPTIONS", "") + ":detect_leaks=0").lstrip(":")
res = subprocess.run([exe, "--out", out, "--scenes", "imageviewer", "--motions", "fixation", "--images",
                      "nosuchpicture", "--quick", "--no-progress"], capture_output=True, text=True, timeout=60,
                     env=env)
print(res.stderr)
assert res.returncode == 2, f"steadyxr-eval exited {res.returncode}, not 2"
assert "picture 'nosuchpicture' not found" in res.stderr, "no message naming the picture"
assert "nothing was measured" in res.stderr
assert not os.path.exists(out), f"{out} was written"
print("ok")
