"""quadray's command line from Python: a render's GPU time, and `quadray
compare`'s relMSE and FLIP (the benchmark scripts share them; no Mitsuba
needed)."""

import re
import subprocess


def quadray_render(quadray, scene, path, w, h, spp, seed, extra, log=False):
    """quadray's GPU seconds for the render (or, with `log`, what it printed)."""
    cmd = [quadray, "render", scene, "--width", str(w), "--height", str(h), "--spp", str(spp), "--seed",
           str(seed), "--no-denoise", "-o", path] + extra
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stderr
    return out if log else float(re.search(r"spp, ([0-9.]+) s on ", out).group(1))


def compare(quadray, reference, test):
    """relMSE on linear radiance and mean FLIP of EXR `test` against EXR
    `reference` (`quadray compare`)."""
    out = subprocess.run([quadray, "compare", reference, test], check=True, capture_output=True, text=True).stdout
    flip = float(re.search(r"FLIP ([0-9.eE+-]+)", out).group(1))
    return float(re.search(r"relative MSE ([0-9.eE+-]+)", out).group(1)), flip


def command_line(script, args):
    """The command that ran `script` with the parsed `args`, every flag
    spelled out, defaults included (a switch that is on bare, one that is
    off left out)."""
    flags = [f"--{k.replace('_', '-')}" + ("" if isinstance(v, bool) else f" {' '.join(v) if isinstance(v, list) else v}")
             for k, v in vars(args).items() if v is not False]
    return f"python3 {script} " + " ".join(flags)


def relmse(quadray, reference, test):
    """relMSE of EXR `test` against EXR `reference` on linear radiance."""
    return compare(quadray, reference, test)[0]
