#!/usr/bin/env python3
"""Adversarial probe of the program's contract: imported files, solutions, states, exports,
signals, memory and work limits, studies, `--set` and friction keys, as an adversary and a
careless user would try them.

usage: contract_probe.py SSN_BINARY SCENES_DIR
PROBE_FAST=1 leaves out the cases that are heavy by design (they check that a work estimate
refuses a run that would take minutes to hours; each may take up to its time limit when the
estimate lets it through); PROBE_SKIP="name;name" leaves out cases by name.
The exit code is 0 when no case breaks, 1 otherwise.
Every case runs in a fresh directory; a case "breaks" when the program panics, aborts,
is killed by a signal, hangs past its time limit, exits with a code other than the
expected one, writes NaN/null numbers, or replaces an input.
"""
import json, os, shutil, signal, subprocess, sys, tempfile, time

S = os.path.abspath(sys.argv[1])
SCENES = os.path.abspath(sys.argv[2])

CHAIN_K = "%%MatrixMarket matrix coordinate real symmetric\n3 3 5\n1 1 2\n2 1 -1\n2 2 2\n3 2 -1\n3 3 1\n"
CHAIN_M = "%%MatrixMarket matrix coordinate real general\n3 3 2\n1 1 1\n2 2 1\n"
CHAIN_F = "%%MatrixMarket matrix coordinate real general\n3 1 1\n2 1 1.0\n"
CHAIN_SCENE = ('title = "chain"\n[model]\nmass = "M.mtx"\nstiffness = "K.mtx"\n[damping]\nzeta = 0.02\n'
               '[forcing]\nvector = "f.mtx"\namplitude = 0.1\n{extra}\n[[contact.point]]\ndof = 3\ngap = 0.05\n')
ROD = "[rod]\nelements = {n}\nmass = \"modified\"\n{rod}\n[forcing]\namplitude = 0.04\n{rest}\n"


def chain(d, extra="", k=CHAIN_K, m=CHAIN_M, f=CHAIN_F, tail=""):
    for name, text in [("K.mtx", k), ("M.mtx", m), ("f.mtx", f)]:
        if text is not None:
            open(os.path.join(d, name), "w").write(text)
    open(os.path.join(d, "model.toml"), "w").write(CHAIN_SCENE.format(extra=extra) + tail)
    return "model.toml"


def edited_chain(d, edit):
    """The chain scene with its text passed through `edit`."""
    path = os.path.join(d, chain(d))
    text = edit(open(path).read())
    open(path, "w").write(text)
    return "model.toml"


def rod(d, n=20, rod="", rest="[contact]\ngap = 0.5", name="rod.toml"):
    open(os.path.join(d, name), "w").write(ROD.format(n=n, rod=rod, rest=rest))
    return name


CASES = []


HEAVY = set()


def case(name, expect, timeout=30, heavy=False):
    def wrap(fn):
        CASES.append((name, expect, timeout, fn))
        if heavy:
            HEAVY.add(name)
        return fn
    return wrap


def run(d, args, timeout, env=None, shell_prefix=None, stdout=None):
    full_env = dict(os.environ)
    full_env.update(env or {})
    cmd = [S] + args
    if shell_prefix:
        cmd = ["sh", "-c", shell_prefix + " exec " + " ".join("'" + a + "'" for a in cmd)]
    start = time.time()
    try:
        p = subprocess.run(cmd, cwd=d, capture_output=stdout is None, stdout=stdout,
                           stderr=subprocess.PIPE if stdout is not None else None,
                           timeout=timeout, env=full_env)
    except subprocess.TimeoutExpired:
        return None, b"", b"", time.time() - start
    return p.returncode, p.stdout or b"", p.stderr or b"", time.time() - start


def keep(d, *names):
    return {n: open(os.path.join(d, n), "rb").read() for n in names}


# ---- inputs overwritten, special files, memory -------------------------------------------
@case("--csv on the scene's K.mtx", 2)
def _(d):
    s = chain(d); before = keep(d, "K.mtx")
    return ["solve", s, "--csv", "K.mtx"], {}, lambda: keep(d, "K.mtx") == before


@case("--state on the scene's f.mtx", 2)
def _(d):
    s = chain(d); before = keep(d, "f.mtx")
    return ["solve", s, "--state", "f.mtx"], {}, lambda: keep(d, "f.mtx") == before


@case("export-model into the scene's own directory", 2)
def _(d):
    s = chain(d); before = keep(d, "K.mtx", "M.mtx", "f.mtx")
    return ["export-model", s, "."], {}, lambda: keep(d, "K.mtx", "M.mtx", "f.mtx") == before


@case("K.mtx a FIFO", 2, timeout=20)
def _(d):
    s = chain(d, k=None); os.mkfifo(os.path.join(d, "K.mtx"))
    return ["solve", s], {}, None


for dev in ["/dev/zero", "/dev/urandom", "/dev/null"]:
    @case(f"K.mtx -> {dev}", 2, timeout=20)
    def _(d, dev=dev):
        s = chain(d, k=None); os.symlink(dev, os.path.join(d, "K.mtx"))
        return ["solve", s], {}, None


for lim in ["4000000", "6000000"]:
    @case(f"1e6 elements under ulimit -v {lim}", 2, timeout=30)
    def _(d, lim=lim):
        s = rod(d, n=1000000)
        return ["solve", s], {"__ulimit": lim}, None


for v in ["lots", "-5", "inf", "nan", "", "1e400"]:
    @case(f"SSN_MEMORY_LIMIT={v!r}", 2)
    def _(d, v=v):
        return ["solve", rod(d)], {"SSN_MEMORY_LIMIT": v}, None

for v in ["x", "0", "-1"]:
    @case(f"SSN_WORK_LIMIT={v!r}", 2)
    def _(d, v=v):
        return ["solve", rod(d)], {"SSN_WORK_LIMIT": v}, None


# ---- work estimates: refused (2) or finished within the time limit ------------------------
def pts(nodes, key="node"):
    return "".join(f"[[contact.point]]\n{key} = {n}\ngap = 0.5\n" for n in nodes)


@case("10,000 contact points on a rod", (0, 1, 2), timeout=30, heavy=True)
def _(d):
    return ["solve", rod(d, n=10000, rest="[damping]\nzeta = 0.01\n" + pts(range(1, 10001)))], {}, None


@case("solutions at H = 2000", (0, 1, 2), timeout=30, heavy=True)
def _(d):
    return ["solutions", rod(d, rest="[damping]\nzeta = 0.01\n[contact]\ngap = 0.5\n[solver]\nharmonics = 2000\n"
                                    "[sweep]\nomega_ratio_from = 0.5\nomega_ratio_to = 1.5")], {}, None


@case("beam sweep at H = 1000", (0, 1, 2), timeout=30, heavy=True)
def _(d):
    shutil.copytree(os.path.join(SCENES, "beam"), os.path.join(d, "beam"))
    text = open(os.path.join(SCENES, "beam_tip_stop.toml")).read().replace("harmonics = 20", "harmonics = 1000")
    open(os.path.join(d, "b.toml"), "w").write(text)
    return ["sweep", "b.toml"], {}, None


@case("scene-check of 1e6 elements", (0, 2), timeout=30, heavy=True)
def _(d):
    return ["scene-check", rod(d, n=1000000)], {}, None


@case("march steps_per_period = 1048576", 2, timeout=30)
def _(d):
    return ["solve", rod(d, n=1000, rest="[contact]\ngap = 0.5\n[solver]\nmethod = \"march\"\nsteps_per_period = 1048576")], {}, None


@case("march on 1e5 elements", 2, timeout=30)
def _(d):
    return ["solve", rod(d, n=100000, rest="[contact]\ngap = 0.5\n[solver]\nmethod = \"march\"")], {}, None


@case("penalty HB at H = 2000 on 1,000 elements", (0, 1, 2), timeout=30, heavy=True)
def _(d):
    return ["solve", rod(d, n=1000, rest="[contact]\ngap = 0.5\n[solver]\nmethod = \"penalty-hb\"\nharmonics = 2000")], {}, None


@case("sweep max_points = 1e6, steps 1e-5", 2, timeout=30)
def _(d):
    return ["sweep", rod(d, n=1000, rest="[damping]\nzeta = 0.01\n[contact]\ngap = 0.5\n[sweep]\nomega_ratio_from = 0.5\n"
                                      "omega_ratio_to = 2.0\nstep = 1e-5\nmin_step = 1e-5\nmax_step = 1e-5\nmax_points = 1000000")], {}, None


# ---- exit codes, numbers and files ------------------------------------------------------
@case("solutions, undamped rod at 1.14 omega_1", (0, 1))
def _(d):
    return ["solutions", rod(d, rest="omega_ratio = 1.14\n[contact]\ngap = 0.5\n[sweep]\nomega_ratio_from = 0.5\nomega_ratio_to = 1.5")], {}, None


@case("solutions, max_points = 2", 1)
def _(d):
    return ["solutions", rod(d, rest="omega_ratio = 1.0\n[damping]\nzeta = 0.01\n[contact]\ngap = 0.5\n[sweep]\n"
                                    "omega_ratio_from = 0.5\nomega_ratio_to = 1.5\nmax_points = 2")], {}, None


@case("sweep of the rod with 3,000 elements", 0, timeout=300)
def _(d):
    return ["sweep", rod(d, n=3000, rest="[damping]\nzeta = 0.01\n[contact]\ngap = 0.5\n[sweep]\nomega_ratio_from = 0.8\nomega_ratio_to = 1.2")], {}, None


for label, rest in [
    ("omega_ratio = 1e300", "omega_ratio = 1e300\n[contact]\ngap = 0.5"),
    ("zeta = 1e300", "[damping]\nzeta = 1e300\n[contact]\ngap = 0.5"),
    ("alpha = 1e300", "[damping]\nalpha = 1e300\n[contact]\ngap = 0.5"),
    ("march max_periods = 1", "[contact]\ngap = 0.5\n[solver]\nmethod = \"march\"\nmax_periods = 1"),
    ("omega_ratio = 5e-324", "omega_ratio = 5e-324\n[contact]\ngap = 0.5"),
    ("amplitude-like gap 1e300", "[contact]\ngap = 1e300"),
]:
    @case(label, 2)
    def _(d, rest=rest):
        return ["solve", rod(d, rest=rest), "--json"], {}, None


@case("f.mtx entry 1e300", 2)
def _(d):
    s = chain(d, f="%%MatrixMarket matrix coordinate real general\n3 1 1\n2 1 1e300\n")
    return ["solve", s, "--json"], {}, None


@case("K and M scaled by 1e300", 2)
def _(d):
    k = CHAIN_K.replace(" 2\n", " 2e300\n").replace(" -1\n", " -1e300\n").replace(" 1\n", " 1e300\n")
    s = chain(d, k=k)
    return ["solve", s, "--json"], {}, None


@case("--start with a coefficient of 1.7e308", 2)
def _(d):
    s = chain(d)
    run(d, ["solve", s, "--state", "st.json"], 30)
    doc = json.load(open(os.path.join(d, "st.json")))
    doc["displacement"][0] = 1.7e308
    json.dump(doc, open(os.path.join(d, "bad.json"), "w"))
    return ["solve", s, "--start", "bad.json", "--json"], {}, None


for h in [2 ** 63, 2 ** 64 - 1, 2 ** 64, -1]:
    @case(f"state harmonics = {h}", 2)
    def _(d, h=h):
        s = chain(d)
        run(d, ["solve", s, "--state", "st.json"], 30)
        text = open(os.path.join(d, "st.json")).read()
        doc = json.loads(text)
        text = text.replace(f'"harmonics": {doc["harmonics"]}', f'"harmonics": {h}').replace(
            f'"harmonics":{doc["harmonics"]}', f'"harmonics":{h}')
        open(os.path.join(d, "bad.json"), "w").write(text)
        return ["solve", s, "--start", "bad.json"], {}, None


@case("undamped rod at its first natural frequency, no contact", 2)
def _(d):
    return ["solve", rod(d, rest="omega_ratio = 1.0")], {}, None


@case("export-model with hostile title, read back", 0)
def _(d):
    s = chain(d)
    text = open(os.path.join(d, s)).read().replace('title = "chain"', 'title = "a\\u00a0e\\u0301\\u007f\\u001b[1m\\u200b\\u202e\\"\\\\"')
    open(os.path.join(d, s), "w").write(text)
    os.mkdir(os.path.join(d, "out"))

    def check():
        return run(d, ["scene-check", "out/scene.toml"], 30)[0] == 0
    return ["export-model", s, "out"], {}, check


@case("exported banner is %%MatrixMarket", 0)
def _(d):
    s = rod(d)
    os.mkdir(os.path.join(d, "out"))
    return ["export-model", s, "out"], {}, lambda: open(os.path.join(d, "out", "K.mtx")).read().startswith("%%MatrixMarket ")


@case("shipped beam/K.mtx banner", None)
def _(d):
    return None, {}, lambda: open(os.path.join(SCENES, "beam", "K.mtx")).read().startswith("%%MatrixMarket ")


@case("--json > /dev/full with --svg", 3)
def _(d):
    s = rod(d, rest="[damping]\nzeta = 0.01\n[contact]\ngap = 0.5")
    return ["solve", s, "--svg", "tip.svg", "--json"], {"__stdout": "/dev/full"}, lambda: not os.path.exists(os.path.join(d, "tip.svg"))


@case("compare --out with the SVG a directory", 3, timeout=300)
def _(d):
    os.makedirs(os.path.join(d, "cmp", "accuracy_cost.svg"))
    return ["compare", os.path.join(SCENES, "paper_fig1_modified_mass.toml"), "--out", "cmp"], {}, \
        lambda: not os.path.exists(os.path.join(d, "cmp", "accuracy_cost.csv"))


@case("scene-check of a [model] scene with ESC in a path", 2)
def _(d):
    s = chain(d)
    text = open(os.path.join(d, s)).read().replace('"M.mtx"', '"M\\u001b[31m.mtx"')
    open(os.path.join(d, s), "w").write(text)
    return ["scene-check", s], {}, None


# ---- messages ---------------------------------------------------------------------------
def mentions(*words):
    return ("mentions", words)


@case("two-sided clearance names the key and 1-based entries", 2)
def _(d):
    s = chain(d, tail="[[contact.point]]\ndof = 3\ngap = -0.06\ndirection = -1\n")
    return ["solve", s], {}, mentions("contact.point.gap", "dof 3", "entry 1", "entry 2")


@case("rod scene direction named", 2)
def _(d):
    open(os.path.join(d, "r.toml"), "w").write(
        "[rod]\nelements = 10\n[forcing]\namplitude = 0.1\n[[contact.point]]\nnode = 10\ngap = 0.5\ndirection = -1\n")
    return ["solve", "r.toml"], {}, mentions("contact.point.direction")


for label, text, words in [
    ("MM one-indexed", "%%MatrixMarket matrix coordinate real general\n3 3 1\n0 1 1\n", ("line 3",)),
    ("MM row out of bounds", "%%MatrixMarket matrix coordinate real general\n3 3 1\n4 1 1\n", ("line 3",)),
    ("MM pattern", "%%MatrixMarket matrix coordinate pattern general\n3 3 1\n1 1\n", ("line 1", "pattern")),
    ("MM 1e9 x 1e9", "%%MatrixMarket matrix coordinate real general\n1000000000 1000000000 1\n1 1 1\n", ("line 2",)),
    ("MM count overflow", "%%MatrixMarket matrix coordinate real general\n3 3 18446744073709551615\n", ("line 2",)),
    ("MM count 2^64", "%%MatrixMarket matrix coordinate real general\n3 3 18446744073709551616\n", ("line 2",)),
    ("MM nan value", "%%MatrixMarket matrix coordinate real general\n3 3 1\n1 1 nan\n", ("line 3",)),
    ("MM lower-case banner accepted", CHAIN_K.replace("%%MatrixMarket", "%%matrixmarket"), ()),
    ("MM empty file", "", ()),
    ("MM only banner", "%%MatrixMarket matrix coordinate real general\n", ()),
    ("MM array format", "%%MatrixMarket matrix array real general\n3 3\n" + "1\n" * 9, ()),
]:
    @case(label, (0, 1, 2) if label.endswith("accepted") or label.startswith("MM array") else 2)
    def _(d, text=text, words=words):
        s = chain(d, k=text)
        return ["solve", s], {}, mentions("K.mtx", *words)


@case("5,000-deep table header", 2)
def _(d):
    open(os.path.join(d, "deep.toml"), "w").write("[" + "a." * 5000 + "a]\n")
    return ["solve", "deep.toml"], {}, mentions("deep.toml", "line")


@case("--entry -1", 2)
def _(d):
    s = chain(d)
    run(d, ["solve", s, "--state", "st.json"], 30)
    return ["solve", s, "--start", "st.json", "--entry", "-1"], {}, mentions("--entry")


@case("solutions with omega outside the window names forcing.omega", 2)
def _(d):
    open(os.path.join(d, "r.toml"), "w").write(
        "[rod]\nelements = 10\nmass = \"modified\"\n[damping]\nzeta = 0.01\n[forcing]\namplitude = 0.1\nomega = 3.0\n"
        "[contact]\ngap = 0.5\n[sweep]\nomega_ratio_from = 0.5\nomega_ratio_to = 0.9\n")
    return ["solutions", "r.toml"], {}, mentions("forcing.omega`")


# ---- adversarial extras -----------------------------------------------------------------
@case("state file a FIFO", 2, timeout=20)
def _(d):
    s = chain(d); os.mkfifo(os.path.join(d, "st.json"))
    return ["solve", s, "--start", "st.json"], {}, None


@case("state file /dev/zero", 2, timeout=20)
def _(d):
    s = chain(d)
    return ["solve", s, "--start", "/dev/zero"], {}, None


@case("matrix file is a directory", 2)
def _(d):
    s = chain(d, k=None); os.mkdir(os.path.join(d, "K.mtx"))
    return ["solve", s], {}, None


@case("matrix path with ..", 2)
def _(d):
    s = chain(d)
    text = open(os.path.join(d, s)).read().replace('"K.mtx"', '"../../../../../../dev/zero"')
    open(os.path.join(d, s), "w").write(text)
    return ["solve", s], {}, None


@case("NaN in a [[contact.point]] gap", 2)
def _(d):
    s = chain(d, tail="[[contact.point]]\ndof = 2\ngap = nan\n")
    return ["solve", s], {}, None


@case("dof = 2^63 in a contact point", 2)
def _(d):
    s = chain(d, tail="[[contact.point]]\ndof = 9223372036854775807\ngap = 0.1\n")
    return ["solve", s], {}, None


@case("stops on both sides, massless dof, from zero (default c)", 0)
def _(d):
    n = 10
    k = f"%%MatrixMarket matrix coordinate real symmetric\n{n} {n} 19\n"
    for i in range(1, 10):
        k += f"{i} {i} {1001.0 if i == 9 else 2.0}\n"
        if i < 9:
            k += f"{i + 1} {i} -1\n"
    k += "10 10 1000\n10 9 -1000\n"
    m = f"%%MatrixMarket matrix coordinate real general\n{n} {n} 9\n" + "".join(f"{i} {i} 1\n" for i in range(1, 10))
    f = f"%%MatrixMarket matrix coordinate real general\n{n} 1 1\n9 1 1\n"
    for name, text in [("K.mtx", k), ("M.mtx", m), ("f.mtx", f)]:
        open(os.path.join(d, name), "w").write(text)
    open(os.path.join(d, "p.toml"), "w").write(
        "[model]\nmass = \"M.mtx\"\nstiffness = \"K.mtx\"\n[damping]\nzeta = 0.02\n[forcing]\nvector = \"f.mtx\"\n"
        "amplitude = 1.0\nomega_ratio = 1.0\n[[contact.point]]\ndof = 10\ngap = 0.01\n[[contact.point]]\ndof = 10\n"
        "gap = 0.01\ndirection = -1\n[[contact.point]]\ndof = 9\ngap = 0.02\n[solver]\nharmonics = 20\n")
    return ["solve", "p.toml", "--json"], {}, None


# ---- studies, --set and friction keys ---------------------------------------------------
def study(d, text, scene_rest="[damping]\nzeta = 0.01\n[contact]\ngap = 0.5\n[solver]\nharmonics = 5"):
    open(os.path.join(d, "study.toml"), "w").write(text)
    return [rod(d, n=10, rest=scene_rest), "study.toml"]


DEEP_KEY = ".".join(["a"] * 60000)


@case("--set key 60,000 levels deep", 2)
def _(d):
    return ["solve", rod(d), "--set", DEEP_KEY + "=1"], {}, mentions("--set")


@case("study grid key 60,000 levels deep", 2)
def _(d):
    return ["study", *study(d, f'[grid]\n"{DEEP_KEY}" = [1]\n'), "--out", "o"], {}, mentions("[grid]", "8 parts")


for keys, values, count in [(64, "[1, 2]", "18446744073709551616"), (41, "[1, 2, 3]", "36472996377170786403")]:
    @case(f"study grid of {keys} keys x {values}", 2)
    def _(d, keys=keys, values=values, count=count):
        grid = "".join(f'"forcing.k{k}" = {values}\n' for k in range(keys))
        return ["study", *study(d, "[grid]\n" + grid), "--out", "o"], {}, mentions(count + " cases")


for samples, size, named in [("10000000", "", "random.samples"), ("1000000", "size = 100\n", "values")]:
    @case(f"study of {samples} random samples {size.strip()}", 2)
    def _(d, samples=samples, size=size, named=named):
        text = (f"[random]\nsamples = {samples}\nseed = 1\n[random.keys.\"forcing.amplitude\"]\n"
                f"distribution = \"uniform\"\nlow = 0.01\nhigh = 0.02\n{size}")
        return ["study", *study(d, text), "--out", "o"], {}, mentions(named)


for label, text, named in [
    ("grid key repeated in [[case]]", '[grid]\n"forcing.amplitude" = [0.01]\n[[case]]\n"forcing.amplitude" = 0.02\n', "also in [grid]"),
    ("grid key with a leading space", '[grid]\n" forcing.amplitude" = [0.01]\n[[case]]\n"forcing.amplitude" = 0.02\n', "also in [grid]"),
    ('run = "sweep" without [sweep]', 'run = "sweep"\n[grid]\n"forcing.amplitude" = [0.01]\n', "[sweep]"),
]:
    @case(f"study {label}", 2)
    def _(d, text=text, named=named):
        return ["study", *study(d, text), "--out", "o"], {}, mentions(named)


for jobs in ["65535", "-1"]:
    @case(f"study --jobs {jobs}", 2)
    def _(d, jobs=jobs):
        return ["study", *study(d, '[grid]\n"forcing.amplitude" = [0.01]\n'), "--out", "o", "--jobs", jobs], {}, mentions("--jobs")


for var, value in [("SSN_WORK_LIMIT", "x"), ("SSN_MEMORY_LIMIT", "-5")]:
    @case(f"study with {var}={value}", 2)
    def _(d, var=var, value=value):
        return ["study", *study(d, '[grid]\n"forcing.amplitude" = [0.01]\n'), "--out", "o"], {var: value}, \
            ("mentions", (var,))


for cases in ["18446744073709551615", "200000000", "0"]:
    @case(f"study merge with cases = {cases}", 2)
    def _(d, cases=cases):
        run(d, ["study", *study(d, '[grid]\n"forcing.amplitude" = [0.01, 0.02]\n'), "--out", "o"], 30)
        path = os.path.join(d, "o", "study.json")
        text = open(path).read().replace('"cases": 2,', f'"cases": {cases},')
        open(path, "w").write(text)
        return ["study", "merge", "o"], {}, mentions("`cases`")


for label, record in [("of another study", None), ("holding only the case", '{"case": 1}')]:
    @case(f"study merge with a record {label}", 2)
    def _(d, record=record):
        run(d, ["study", *study(d, '[grid]\n"forcing.amplitude" = [0.01, 0.02]\n'), "--out", "o"], 30)
        path = os.path.join(d, "o", "cases", "case-000001.json")
        if record is None:
            doc = json.load(open(path))
            doc["study"] = "0123456789abcdef"
            record = json.dumps(doc)
        open(path, "w").write(record)
        return ["study", "merge", "o"], {}, mentions("case-000001.json")


for line, key in [("friction = 0.3", "friction"), ("tangent_dofs = [1]", "tangent_dofs"),
                  ("dofs = [1, 2]", "dofs"), ("coefficients = [1.0]", "coefficients")]:
    @case(f"rod contact with {key}", 2)
    def _(d, line=line, key=key):
        s = rod(d, rest=f"[[contact.point]]\nnode = 20\ngap = 0.5\n{line}")
        return ["solve", s], {}, mentions(f"contact.point.{key}")


for label, normal, tangent in [("equal", "[1.0, -1.0]", "[1.0, -1.0]"), ("parallel", "[1.0, -1.0]", "[-2.0, 2.0]")]:
    @case(f"tangent row {label} to the normal row", 2)
    def _(d, normal=normal, tangent=tangent):
        s = chain(d, tail=f"[[contact.point]]\ndofs = [1, 2]\ncoefficients = {normal}\ngap = 0.1\n"
                          f"friction = 0.3\ntangent_dofs = [1, 2]\ntangent_coefficients = {tangent}\n")
        return ["solve", s], {}, mentions("contact.point.tangent_coefficients", "parallel")


@case("contact coefficients of 1e-300", 2)
def _(d):
    s = chain(d, tail="[[contact.point]]\ndofs = [1, 2]\ncoefficients = [1e-300, -1e-300]\ngap = 0.1\n")
    return ["solve", s], {}, mentions("contact.point.coefficients")


@case("scene-check of 2,000 elements with a stop on every node", 0, timeout=30)
def _(d):
    return ["scene-check", rod(d, n=2000, rest="[damping]\nzeta = 0.01\n" + pts(range(1, 2001)))], {}, None


@case("export-model of 2,000 elements with a stop on every node", 0, timeout=30)
def _(d):
    return ["export-model", rod(d, n=2000, rest="[damping]\nzeta = 0.01\n" + pts(range(1, 2001))), "out"], {}, None


# ---- sweep units, [cyclic], [modes], 3-D contact and [model] keys ------------------------
for label, window, key in [
        ("omega_from negative", "omega_from = -1.0\nomega_to = 2.0", "sweep.omega_from"),
        ("frequency_hz_from NaN", "frequency_hz_from = nan\nfrequency_hz_to = 0.3", "sweep.frequency_hz_from"),
        ("omega_from at 1e300", "omega_from = 1e300\nomega_to = 1.7e308", "sweep.omega_from"),
        ("frequency_hz_to below the range", "frequency_hz_from = 1e-300\nfrequency_hz_to = 1e-299",
         "sweep.frequency_hz_from"),
        ("two units", "omega_ratio_from = 0.5\nomega_ratio_to = 1.5\nomega_from = 1.0", "sweep.omega_from"),
        ("a lone frequency_hz_from", "frequency_hz_from = 0.2", "sweep.frequency_hz_to")]:
    @case(f"[sweep] {label}", 2)
    def _(d, window=window, key=key):
        return ["sweep", rod(d, rest=f"[contact]\ngap = 0.5\n[sweep]\n{window}")], {}, mentions(key)


for label, cyclic, key in [
        ("sectors = 0", "sectors = 0\nengine_order = 0\nleft = [1]\nright = [2]", "cyclic.sectors"),
        ("engine_order = -1", "sectors = 4\nengine_order = -1\nleft = [1]\nright = [2]", "cyclic.engine_order"),
        ("an interface dof past the sector", "sectors = 4\nengine_order = 1\nleft = [1]\nright = [99]",
         "cyclic.right` = 99"),
        ("a dof on both sides", "sectors = 4\nengine_order = 1\nleft = [1]\nright = [1]", "cyclic.right` = 1"),
        ("dof 0", "sectors = 4\nengine_order = 1\nleft = [0]\nright = [2]", "cyclic.left"),
        ("sides of two lengths", "sectors = 4\nengine_order = 1\nleft = [1]\nright = [2, 3]", "cyclic.right"),
        ("nodes without a dof_map", "sectors = 4\nengine_order = 1\nleft_nodes = [1]\nright_nodes = [2]",
         "cyclic.left_nodes")]:
    @case(f"[cyclic] {label}", 2)
    def _(d, cyclic=cyclic, key=key):
        return ["solve", edited_chain(d, lambda text: text + f"[cyclic]\n{cyclic}\n")], {}, mentions(key)


for label, modes, key in [
        ("mode = 0", "mode = 0\nenergy_from = 0.1\nenergy_to = 1.0", "modes.mode"),
        ("max_points = 0", "max_points = 0\nenergy_from = 0.1\nenergy_to = 1.0", "modes.max_points"),
        ("energy_from negative", "energy_from = -1.0\nenergy_to = 1.0", "modes.energy_from"),
        ("amplitude_to NaN", "amplitude_from = 1.0\namplitude_to = nan", "modes.amplitude_to"),
        ("two ranges", "energy_from = 0.1\nenergy_to = 1.0\namplitude_from = 0.1", "modes.amplitude_from")]:
    @case(f"[modes] {label}", 2)
    def _(d, modes=modes, key=key):
        return ["modes", chain(d, extra=f"[modes]\n{modes}")], {}, mentions(key)


for label, point, key in [
        ("tangent2_dofs without friction", "tangent2_dofs = [1]", "contact.point.friction"),
        ("tangent2_dofs without tangent coefficients", "friction = 0.3\ntangent_dofs = [1]\ntangent2_dofs = [2]",
         "contact.point.tangent_coefficients"),
        ("component without node", "component = 9", "contact.point.component"),
        ("node beside dof", "node = 1", "contact.point.node")]:
    @case(f"contact point {label}", 2)
    def _(d, point=point, key=key):
        return ["solve", chain(d, tail=point + "\n")], {}, mentions(key)


for label, line, key in [("format of another name", 'format = "xyz"', "format"),
                         ("calculix without a dof_map", 'format = "calculix"', "model.dof_map")]:
    @case(f"[model] {label}", 2)
    def _(d, line=line, key=key):
        edit = lambda text: text.replace("[model]\n", f"[model]\n{line}\n", 1)
        return ["solve", edited_chain(d, edit)], {}, mentions(key)


NUMERIC = ("residual", "tip", "amplitude", "force", "omega", "penetration", "displacement")


def null_numbers(out):
    """The keys of numbers written as `null` in a JSON document (a non-finite number)."""
    try:
        doc = json.loads(out)
    except ValueError:
        return []
    found = []

    def walk(v, key=""):
        if isinstance(v, dict):
            for k, x in v.items():
                walk(x, k)
        elif isinstance(v, list):
            for x in v:
                walk(x, key)
        elif v is None and any(w in key for w in NUMERIC):
            found.append(key)

    walk(doc)
    return found


def main():
    breaks = 0
    skip = set(os.environ.get("PROBE_SKIP", "").split(";"))
    if os.environ.get("PROBE_FAST") == "1":
        skip |= HEAVY
    for name, expect, timeout, fn in [c for c in CASES if c[0] not in skip]:
        d = tempfile.mkdtemp(prefix="probe-")
        try:
            args, env, check = fn(d)
            if args is None:
                ok = check()
                print(("ok   " if ok else "BREAK"), name)
                breaks += not ok
                continue
            prefix = f"ulimit -v {env.pop('__ulimit')};" if "__ulimit" in env else None
            stdout = open(env.pop("__stdout"), "w") if "__stdout" in env else None
            code, out, err, secs = run(d, args, timeout, env, prefix, stdout)
            err_text = err.decode("utf-8", "replace")
            why = []
            if code is None:
                why.append(f"no end within {timeout} s")
            else:
                want = expect if isinstance(expect, tuple) else (expect,)
                if code not in want:
                    why.append(f"exit {code}, expected {expect}")
                if code < 0 or code >= 128:
                    why.append(f"killed by signal ({code})")
                if "panicked" in err_text:
                    why.append("panic")
                if b"NaN" in out or b"Infinity" in out or null_numbers(out):
                    why.append("NaN/null in output")
            if callable(check) and code is not None and not check():
                why.append("check failed (input replaced or output left)")
            if isinstance(check, tuple) and code == 2:
                for w in check[1]:
                    if w not in err_text:
                        why.append(f"`{w}` not named")
            line = err_text.strip().splitlines()[0][:110] if err_text.strip() else ""
            print(("ok   " if not why else "BREAK"), f"{name} [{code}, {secs:.1f} s]", "; ".join(why), "|", line)
            breaks += bool(why)
        finally:
            shutil.rmtree(d, ignore_errors=True)
    print(f"{breaks} breaks of {len(CASES) - len(skip & {c[0] for c in CASES})} cases")
    return breaks


sys.exit(1 if main() else 0)
