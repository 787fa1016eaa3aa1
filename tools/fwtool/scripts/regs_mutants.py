#!/usr/bin/env python3
"""Every register address and bit of the register layer changed, one at a time.

Run from the workspace root: `python3 tools/fwtool/scripts/regs_mutants.py`. For each
mutant of `src/regs.rs` and `src/regs/*.rs` (an integer literal in code one higher; a
peripheral block swapped for another of its type, ADC1 for ADC2, GPIOA for GPIOB, ...; a
`true` for `false`; a register field's accessor for a sibling's, `set_hseon` for
`set_pllon`, `teif` for `htif`, ...) it runs `cargo test -p drive-monitor --test firmware -- registers::`
and reports whether the test failed (caught), the build failed (unviable) or the test passed
(missed), then restores the file. Exits 1 when a mutant is missed. cargo-mutants does not
make these mutants (it replaces function bodies and operators, not literals or paths).
"""
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
FILES = [ROOT / "src/regs.rs"] + sorted((ROOT / "src/regs").glob("*.rs"))
TEST = ["cargo", "test", "-q", "-p", "drive-monitor", "--test", "firmware", "--", "registers::"]

# Accessors swapped within each group (same signature, another field of the register).
SIBLINGS = [
    ["set_hseon", "set_pllon", "set_csson"],
    ["hserdy", "pllrdy"],
    ["pvu", "rvu"],
    ["set_ovr", "set_eoc", "set_eos"],
    ["ovr()", "eoc()", "eos()"],
    ["set_teif", "set_htif", "set_tcif", "set_gif"],
    ["teif(", "tcif("],
    ["set_eccd", "set_eccc"],
    ["set_jeos", "set_jeoc"],
    ["jeos()", "jeoc()"],
    ["apb1lfzr", "apb1hfzr"],
    ["Dmaen::ENABLE", "Dmaen::DISABLE"],
    ["Dmacfg::CIRCULAR", "Dmacfg::ONE_SHOT"],
    ["Ts::ITR0", "Ts::ITR1"],
    ["CcmrInputCcs::TRC", "CcmrInputCcs::TI4"],
    ["CYCLES24_5", "CYCLES12_5"],
    ["CYCLES247_5", "CYCLES640_5"],
    ["Moder::OUTPUT", "Moder::ALTERNATE"],
    ["pac::ADC1)", "pac::ADC3)"],
    ["pac::ADC2)", "pac::ADC4)"],
    ["pac::GPIOA)", "pac::GPIOB)"],
    ["pac::TIM4)", "pac::TIM3)"],
    ["pac::DMA1)", "pac::DMA2)"],
    ["ccr(2)", "ccr(1)"],
    ["cr().read().en()", "cr().read().teie()"],
]


def code_part(line):
    """The line up to a `//` comment (doc comments are comments)."""
    return line.split("//")[0]


def mutants(text):
    lines = text.split("\n")
    for n, line in enumerate(lines):
        code = code_part(line)
        if not code.strip() or code.lstrip().startswith(("use ", "pub mod", "mod ")):
            continue
        for m in re.finditer(r"(?<![\w.])(0x[0-9A-Fa-f_]+|\d[\d_]*)(?![\w.])", code):
            lit = m.group(1)
            value = int(lit.replace("_", ""), 0)
            new = str(value + 1)
            yield n, m.start(), lit, new
        for m in re.finditer(r"\b(true|false)\b", code):
            yield n, m.start(), m.group(1), "false" if m.group(1) == "true" else "true"
        for group in SIBLINGS:
            for i, name in enumerate(group):
                start = code.find(name)
                while start != -1:
                    for other in group[i + 1:] + group[:i]:
                        yield n, start, name, other
                        break
                    start = code.find(name, start + 1)


def run(path, text, n, col, old, new):
    lines = text.split("\n")
    line = lines[n]
    lines[n] = line[:col] + new + line[col + len(old):]
    path.write_text("\n".join(lines))
    try:
        out = subprocess.run(TEST, cwd=ROOT, capture_output=True, text=True)
    finally:
        path.write_text(text)
    if out.returncode == 0:
        return "MISSED"
    if "test result: FAILED" in out.stdout or "panicked" in out.stdout + out.stderr:
        return "caught"
    return "unviable"


def main():
    counts = {"caught": 0, "unviable": 0, "MISSED": 0}
    for path in FILES:
        text = path.read_text()
        for n, col, old, new in mutants(text):
            verdict = run(path, text, n, col, old, new)
            counts[verdict] += 1
            rel = path.relative_to(ROOT)
            print(f"{verdict:8} {rel}:{n + 1}: {old} -> {new}", flush=True)
    viable = counts["caught"] + counts["MISSED"]
    print(f"mutants {sum(counts.values())}, unviable {counts['unviable']}, "
          f"caught {counts['caught']} of {viable} viable")
    return 1 if counts["MISSED"] else 0


if __name__ == "__main__":
    sys.exit(main())
