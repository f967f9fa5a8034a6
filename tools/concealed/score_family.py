#!/usr/bin/python3
"""Scores `pliant diagnose` on a concealed family (any directory of case_* recordings with a
truth.json each, e.g. the msm-world family or examples/concealed).

Usage: /usr/bin/python3 tools/concealed/score_family.py PLIANT DIR [--model msm|fem]
       [--estimate] [--timeout 600]

For every case the binary's `diagnose CASE --json OUT -q` runs first; only after all of them
have run is any truth.json opened. Printed: one line per case (truth, effect size, verdict,
named effect, held-out improvement, runtime), a confusion matrix (rows truth, columns what was
named, `consistent` for verdict consistent, `unknown`, `error` when the binary failed), the share
of effect cases named right, the number of NAMED false alarms on no-effect cases (an `unknown`
is not a named alarm), and the mean held-out improvement on effect cases.
With --estimate, `estimate CASE --json -` also runs on the no-effect cases and its msm_beta is
compared with the truth.
A report, not a test: the exit status is 0 whatever the score (2 only for bad arguments).
"""

import argparse
import glob
import json
import os
import subprocess
import sys
import tempfile
import time

EFFECTS = ["plasticity", "viscosity", "friction", "gravity", "heterogeneity", "stiffening", "latency", "none"]
COLUMNS = ["plasticity", "viscosity", "friction", "gravity", "heterogeneity", "stiffening", "latency",
           "unknown", "consistent", "error"]


def run_diagnose(pliant, case, model, timeout):
    """The binary's answer for one case: dict with verdict, effect, improvement, seconds."""
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "diagnosis.json")
        cmd = [pliant, "diagnose", case, "--json", out, "-q"]
        if model != "msm":
            cmd += ["--model", model]
        start = time.time()
        try:
            proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
        except subprocess.TimeoutExpired:
            return {"named": "error", "error": f"timeout after {timeout} s", "seconds": timeout}
        seconds = time.time() - start
        if proc.returncode != 0 or not os.path.exists(out):
            message = (proc.stderr or proc.stdout).strip().splitlines()
            return {"named": "error", "error": f"exit {proc.returncode}: {message[-1] if message else ''}",
                    "seconds": seconds}
        with open(out) as f:
            doc = json.load(f)
    verdict = doc.get("verdict")
    effect = doc.get("effect") or "none"
    named = "consistent" if verdict == "consistent" or effect == "none" else effect
    baseline = doc.get("baseline", {})
    return {"named": named, "verdict": verdict, "improvement": doc.get("improvement"),
            "baseline_rms": baseline.get("rms"), "noise_rms": doc.get("noise_rms"),
            "baseline_beta": baseline.get("parameters", {}).get("msm_beta"), "seconds": seconds}


def run_estimate(pliant, case, timeout):
    try:
        proc = subprocess.run([pliant, "estimate", case, "--json", "-", "-q"], capture_output=True,
                              text=True, timeout=timeout)
        doc = json.loads(proc.stdout)
    except (subprocess.TimeoutExpired, json.JSONDecodeError) as err:
        return {"error": str(err)[:80]}
    return doc


def find_beta(doc):
    """msm_beta from an estimate document (looked up by name, wherever it sits)."""
    if isinstance(doc, dict):
        for key in ("parameters", "estimate", "result"):
            if isinstance(doc.get(key), dict) and "msm_beta" in doc[key]:
                value = doc[key]["msm_beta"]
                return value.get("value") if isinstance(value, dict) else value
        if "msm_beta" in doc:
            value = doc["msm_beta"]
            return value.get("value") if isinstance(value, dict) else value
    return None


def estimate_misfit(doc, dim):
    """The estimate's rms residual over the noise a perfect model would leave (its per-coordinate
    noise std times sqrt(dimension)); about 1 when the fitted model reproduces the recording."""
    try:
        return doc["rms"] / (doc["diagnostics"]["noise_std"] * dim ** 0.5)
    except (KeyError, TypeError, ZeroDivisionError):
        return None


def dimension(case):
    with open(os.path.join(case, "recording.json")) as f:
        return json.load(f).get("dimension", 3)


def fmt(x, spec):
    if x is None:
        width = "".join(ch for ch in spec.split(".")[0] if ch.isdigit())
        return format("-", ">" + width)
    return format(x, spec)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("pliant")
    ap.add_argument("family")
    ap.add_argument("--model", default="msm", choices=["msm", "fem"])
    ap.add_argument("--estimate", action="store_true", help="also estimate msm_beta on the no-effect cases")
    ap.add_argument("--timeout", type=float, default=600)
    args = ap.parse_args()
    cases = sorted(d for d in glob.glob(os.path.join(args.family, "case_*")) if os.path.isdir(d))
    if not cases:
        print(f"score_family.py: no case_* directories in {args.family}", file=sys.stderr)
        sys.exit(2)

    answers = {}
    for case in cases:  # every diagnosis first, blind
        answers[case] = run_diagnose(args.pliant, case, args.model, args.timeout)
        print(f"  diagnosed {os.path.basename(case)} in {answers[case]['seconds']:.1f} s", file=sys.stderr, flush=True)

    truths = {}
    for case in cases:  # only now the answers
        with open(os.path.join(case, "truth.json")) as f:
            truths[case] = json.load(f)

    print(f"{'case':8} {'truth':13} {'scenario':11} {'size':>6} {'verdict':16} {'named':13} "
          f"{'improv':>7} {'base/noise':>10} {'s':>6}  ok")
    confusion = {e: {c: 0 for c in COLUMNS} for e in EFFECTS}
    right = effect_cases = alarms = unknown_on_null = wrong_names = 0
    improvements = []
    for case in cases:
        t, a = truths[case], answers[case]
        truth = t.get("effect", "none")
        size = (t.get("effect_size") or {}).get("rms_over_noise")
        named = a["named"]
        confusion.setdefault(truth, {c: 0 for c in COLUMNS})
        confusion[truth][named if named in COLUMNS else "unknown"] += 1
        ratio = None
        if a.get("baseline_rms") is not None and a.get("noise_rms"):
            ratio = a["baseline_rms"] / a["noise_rms"]
        if truth == "none":
            mark = {"consistent": "yes", "unknown": "unk"}.get(named, "NO")
            alarms += named not in ("consistent", "unknown", "error")
            unknown_on_null += named == "unknown"
        else:
            effect_cases += 1
            ok = named == truth
            mark = "yes" if ok else "NO"
            right += ok
            wrong_names += not ok and named not in ("consistent", "unknown", "error")
            if a.get("improvement") is not None:
                improvements.append(a["improvement"])
        verdict = a.get("verdict") or a.get("error", "")[:16]
        print(f"{os.path.basename(case):8} {truth:13} {t.get('scenario', ''):11} {fmt(size, '6.1f')} "
              f"{verdict:16} {named:13} {fmt(a.get('improvement'), '7.2f')} {fmt(ratio, '10.2f')} "
              f"{a['seconds']:6.1f}  {mark}")
        if "error" in a:
            print(f"         error: {a['error']}")

    print("\nconfusion matrix (rows truth, columns named):")
    short = {"plasticity": "plast", "viscosity": "visc", "friction": "frict", "gravity": "grav",
             "heterogeneity": "hetero", "stiffening": "stiff", "latency": "lat", "unknown": "unkn",
             "consistent": "cons", "error": "err"}
    print(f"{'':14}" + "".join(f"{short[c]:>7}" for c in COLUMNS))
    for e in EFFECTS:
        if e in confusion:
            print(f"{e:14}" + "".join(f"{confusion[e][c]:7d}" for c in COLUMNS))
    nulls = len(cases) - effect_cases
    print(f"\neffect cases named right: {right}/{effect_cases}"
          f" ({100.0 * right / max(effect_cases, 1):.0f} %)")
    print(f"named false alarms on no-effect cases: {alarms}/{nulls} (unknown on no-effect: {unknown_on_null})")
    print(f"wrong names on effect cases (an effect named that is not there): {wrong_names}")
    if improvements:
        print(f"mean held-out improvement on effect cases: {sum(improvements) / len(improvements):.3f}")

    if args.estimate:
        print("\nmsm_beta of `estimate` on the no-effect cases:")
        print(f"{'case':8} {'scenario':11} {'true':>6} {'est':>7} {'error':>7} {'diag':>7}"
              f" {'alpha':>6} {'est':>6} {'steps':>5} {'est':>4} {'rms/noise':>9}")
        errors = []
        for case in cases:
            if truths[case].get("effect") != "none":
                continue
            true_beta = truths[case]["parameters"]["msm_beta"]
            doc = run_estimate(args.pliant, case, args.timeout)
            beta = find_beta(doc)
            alpha = (doc.get("parameters") or {}).get("msm_alpha")
            steps = (doc.get("model_options") or {}).get("steps_per_frame")
            err = None if beta is None else beta - true_beta
            if err is not None:
                errors.append(abs(err))
            print(f"{os.path.basename(case):8} {truths[case].get('scenario', ''):11} {true_beta:6.3f} "
                  f"{fmt(beta, '7.3f')} {fmt(err, '+7.3f')} {fmt(answers[case].get('baseline_beta'), '7.3f')}"
                  f" {truths[case]['parameters'].get('msm_alpha', 1.0):6.2f} {fmt(alpha, '6.2f')}"
                  f" {truths[case].get('steps_per_frame', 1):5d} {steps if steps is not None else '-':>4}"
                  f" {fmt(estimate_misfit(doc, dimension(case)), '9.2f')}")
        if errors:
            print(f"mean |error| {sum(errors) / len(errors):.3f}, max {max(errors):.3f}")
    sys.exit(0)


if __name__ == "__main__":
    main()
