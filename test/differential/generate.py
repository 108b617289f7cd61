#!/usr/bin/env python3
"""Random small classes for CrossRT's differential tester.

Each seed gives one class in the supported subset, written as a user writes one: member vectors
(of floats, ints, and of a struct of two float4 whose fields some maps read),
kernel1D_ loop nests (maps, integer maps, reductions into members and into elements of a member
array or of a local array read after the loop, appends, atomic adds into a member vector, a
member's data() to a kernel) and kernel2D_
nests, and a control function whose host code sits between the kernel calls: member writes,
swaps of member vectors, member vectors' elements read and written, loops that stop early on a
counter the kernels reduce, and a tail that reads the results. Some kernels declare locals that
shadow their parameters. A CRT_SPECIALIZE member (m_mode),
which the Vulkan class's pipelines are compiled for, picks branches in kernels; the tail may change
it, so that the second Run makes the pipelines again. The tester (differential.cpp) runs each class as written, as _CPU, as _ISPC and
as _Vulkan and compares what they leave behind, the way Csmith and YARPGen find miscompilations.

Only the C++ the generated classes run is random; everything else is fixed, so that a mismatch
is the translator's. The programs avoid what C++ or GLSL leave undefined: integers stay small
and masked (no overflow; % and / only of non-negative values by positive constants), floats stay
clamped (no inf, no NaN), and control flow depends on integers only (float sums differ in their
last bits between a sequential loop and the GPU's tree of partial sums).

  generate.py --first SEED --count N --out DIR   writes DIR/diff_<seed>.h/.cpp and DIR/cases.inc
"""
import argparse
import os
import random


class Gen:
    def __init__(self, seed):
        self.r = random.Random(seed)
        self.rm = random.Random(seed * 7919 + 1)  # m_mode's uses and initial value
        self.rs = random.Random(seed * 104729 + 3)  # which kernels declare locals that shadow parameters
        self.rc = random.Random(seed * 15485863 + 7)  # which maps read fields of m_cells (an array of structs)
        self.cells = False
        self.seed = seed
        self.name = f"Diff{seed}"
        self.around = {}  # a kernel's statements before and after its loop nest, by name

    def pick(self, *options):
        return self.r.choice(options)

    # ---- expressions -------------------------------------------------------------------------
    def fexpr(self, depth, leaves):
        if depth == 0 or self.r.random() < 0.3:
            return self.r.choice(leaves)
        a, b = self.fexpr(depth - 1, leaves), self.fexpr(depth - 1, leaves)
        form = self.r.randrange(7)
        if form == 0:
            return f"({a} + {b})"
        if form == 1:
            return f"({a} - {b})"
        if form == 2:
            return f"({a} * {b})"
        if form == 3:
            return f"std::min({a}, {b})"
        if form == 4:
            return f"std::max({a}, {b})"
        if form == 5:
            return f"std::abs({a})"
        return f"({a} / (1.0f + std::abs({b})))"

    def iexpr(self, depth, leaves):
        if depth == 0 or self.r.random() < 0.3:
            return self.r.choice(leaves)
        a, b = self.iexpr(depth - 1, leaves), self.iexpr(depth - 1, leaves)
        form = self.r.randrange(7)
        if form == 0:
            return f"(({a} + {b}) & 1023)"
        if form == 1:
            return f"(({a} - {b}) & 1023)"
        if form == 2:
            return f"(({a} * {b}) & 1023)"
        if form == 3:
            return f"({a} ^ {b})"
        if form == 4:
            return f"(({a} & 1023) % {self.r.randint(2, 9)})"
        if form == 5:
            return f"(({a} & 1023) / {self.r.randint(2, 5)})"
        return f"std::min({a}, {b})"

    # ---- the class ---------------------------------------------------------------------------
    def make(self):
        r = self.r
        self.n = r.choice([1, 7, 64, 100, 255, 256, 257, 1000])
        fleaves = ["m_a[i]", "m_b[i]", "float(i)", "a_q", "m_scale", "0.5f", "2.0f", "1.25f", "-3.0f"]
        ileaves = ["m_i[i]", "i", "a_p", "m_k", "3", "17"]
        kernels = []  # (name, params decl, body lines, call args)
        body = []     # the control function's statements

        def clamp(e):
            return f"std::min(std::max({e}, -1000.0f), 1000.0f)"

        def new_kernel(kind):
            k = len(kernels)
            name = f"kernel1D_{kind}{k}"
            if kind == "Map":
                dst = self.pick("m_a", "m_b")
                value = self.fexpr(3, fleaves)
                if self.rc.random() < 0.6:
                    # Fields of a member vector of structs (two float4 rows), read whole at the
                    # thread's index (ISPC: neighbouring lanes, neighbouring elements) or another.
                    self.cells = True
                    at = self.rc.choice(["i", "i", "(i * 7 + 3) % n"])
                    value += f" + (m_cells[{at}].lo {self.rc.choice(['*', '+', '-'])} m_cells[{at}].hi).{self.rc.choice('xyzw')}"
                line = f"{dst}[i] = {clamp(value)};"
            elif kind == "Int":
                line = f"m_i[i] = {self.iexpr(3, ileaves)} & 1023;"
            elif kind == "Sum":
                line = f"m_sum += {clamp(self.fexpr(2, fleaves))};"
            elif kind == "First":  # one thread writes an element at a constant index (ISPC: a per-lane value at a shared index)
                j, c = r.randrange(self.n), r.randrange(self.n)
                if r.random() < 0.5:
                    value = clamp("m_b[i] * 0.5f + " + self.fexpr(2, fleaves))  # m_b[i]: a value of the thread's own
                    line = f"if (i == {j}) {self.pick('m_a', 'm_b')}[{c}] {self.pick('=', '+=')} {value};"
                else:
                    line = f"if (i == {j}) m_i[{c}] = (i + {self.iexpr(2, ileaves)}) & 1023;"
            elif kind == "Count":
                line = f"m_count += ({self.iexpr(2, ileaves)} % {r.randint(2, 5)} == 0) ? 1 : 0;"
            elif kind == "Max":
                line = f"m_max = std::max(m_max, {clamp(self.fexpr(2, fleaves))});"
            elif kind == "Found":
                line = f"if ({self.iexpr(2, ileaves)} % {r.randint(2, 6)} == 0) m_found.push_back(i);"
            elif kind == "Mode":  # branches on the CRT_SPECIALIZE member: folded in a specialised shader
                c = self.rm.randint(0, 3)
                line = (f"{self.pick('m_a', 'm_b')}[i] = m_mode == {c} ? {clamp(self.fexpr(2, fleaves))} : "
                        f"(m_mode > {c} ? {clamp(self.fexpr(2, fleaves))} : float(m_mode) * 0.5f);")
            elif kind == "Bins":  # elements of a member array reduced: a constant index or one the thread computes
                at = self.pick(str(r.randrange(4)), f"({self.iexpr(2, ileaves)} & 1023) % 4")
                if r.random() < 0.7:
                    line = f"m_bins[{at}] {self.pick('+=', '-=')} {clamp(self.fexpr(2, fleaves))};"
                else:
                    line = f"m_bins[{at}] = std::{self.pick('min', 'max')}(m_bins[{at}], {clamp(self.fexpr(2, fleaves))});"
            elif kind == "LocalBins":  # elements of a local array reduced, its totals added to m_bins after the loop
                at = self.pick(str(r.randrange(3)), f"({self.iexpr(2, ileaves)} & 1023) % 3")
                if r.random() < 0.7:
                    line = f"bins[{at}] += {clamp(self.fexpr(2, fleaves))};"
                else:
                    line = f"bins[{at}] = std::{self.pick('min', 'max')}(bins[{at}], {clamp(self.fexpr(2, fleaves))});"
                # Before the loop nest, one thread halves m_bins in a loop of constant count (not the nest).
                self.around[name] = (["float bins[3] = {0.5f, 0.0f, -1.0f};", "for (int k = 0; k < 4; ++k)", "  m_bins[k] *= 0.5f;"],
                                     ["for (int k = 0; k < 3; ++k)", "  m_bins[k + 1] += bins[k];"])
            elif kind == "Hist":
                line = f"InterlockedAdd(m_hist[({self.iexpr(2, ileaves)} & 1023) % 8], {self.pick('1', 'a_p', 'm_i[i] % 5')});"
            lines = [line]
            if kind in ("Map", "Int", "Sum") and self.rs.random() < 0.25:
                # Locals that shadow the kernel's parameters (valid C++): per element where the
                # parameters are shared, so the generated code must keep them apart.
                # The loop's bound is the per-element a_p, or the kernel's a_p, which every thread
                # shares (ISPC: a uniform loop), in one of the forms a person writes.
                shadow = self.rs.random() < 0.5
                cond = self.rs.choice(["n < a_p", "n + 1 <= a_p", "2 * n < a_p + 1", "n * n < 4 * a_p"])
                lines = (["{"] +
                         ([f"  const int a_p = (m_i[i] & {self.rs.choice([3, 7])}) + 1;  // shadows the parameter a_p"] if shadow else []) +
                         ["  float a_q = 0.0f;                  // shadows a_q",
                          f"  for (int n = 0; {cond}; ++n)      // and n",
                          "    a_q += float(n) * 0.5f;",
                          "  " + line,
                          "}"])
            kernels.append((name, "int n, int a_p, float a_q", lines, "n, a_p, a_q"))
            return name

        def grid_call():
            # A 2D loop nest over w x h = n elements (one of n's factorisations).
            k = len(kernels)
            name = f"kernel2D_Grid{k}"
            h = self.pick(*[d for d in (1, 2, 4, 5, 8, 10) if self.n % d == 0])
            w = self.n // h
            dst = self.pick("m_a", "m_b")
            lines = ["for (int y = 0; y < h; ++y)", "  for (int x = 0; x < w; ++x)", "  {", "    const int i = y * w + x;",
                     f"    {dst}[i] = {clamp(self.fexpr(3, fleaves + ['float(x)', 'float(y)']))};", "  }"]
            kernels.append((name, "int w, int h, int a_p, float a_q", lines, "2d"))
            return f"{name}({w}, {h}, a_p, a_q);"

        def call(kind):
            return f"{new_kernel(kind)}(n, a_p, a_q);"

        # A kernel writing through a pointer: a member's data().
        fill = None
        if r.random() < 0.4:
            fill = "kernel1D_Fill"
            kernels.append((fill, "float* a_out, float a_value, int n", ["a_out[i] = a_value + float(i % 5);"], None))

        def host_vector_use():
            # Host code between kernel calls that reads or writes member vectors' elements.
            j = r.randrange(self.n)
            return self.pick(f"m_a[{j}] = {clamp(f'm_b[{j}] + 1.0f')};",
                             f"m_k = m_i[{j}] % {r.randint(2, 7)};",
                             "for (float& v : m_b)\n  v = std::min(v, 10.0f);",
                             f"for (int j = 0; j < n; j += {r.randint(1, 4)})\n  m_i[j] = (m_i[j] + 1) & 1023;",
                             "m_scale = std::max(std::min(m_a[0], 4.0f), -4.0f);")

        for _ in range(r.randint(2, 5)):
            s = r.randrange(10)
            if s <= 2:
                kind = self.pick("Map", "Map", "Int", "Sum", "Max", "Hist", "Grid", "First", "Bins", "LocalBins")
                if self.rm.random() < 0.3:
                    kind = "Mode"
                body.append(grid_call() if kind == "Grid" else call(kind))
            elif s == 3:
                body.append(f"m_scale = {self.pick('0.5f', '1.5f', 'a_q', '-1.0f')};")
            elif s == 4:
                body.append(self.pick("std::swap(m_a, m_b);", "m_a.swap(m_b);"))
            elif s == 5 and fill:
                body.append(f"{fill}({self.pick('m_a', 'm_b')}.data(), {self.pick('0.25f', 'a_q', '-2.0f')}, n);")
            elif s == 6:
                body.append("m_found.clear();")
                body.append(call("Found"))
            elif s == 7:
                # Iterate until a counter the kernels reduce passes a bound, at most a_p rounds.
                limit = r.randint(1, max(1, self.n))
                inner = [call(self.pick("Map", "Int")), "m_count = 0;", call("Count")]
                if r.random() < 0.5:
                    inner.append(self.pick("std::swap(m_a, m_b);", "m_a.swap(m_b);"))
                if r.random() < 0.3:
                    inner.insert(r.randint(0, len(inner)), host_vector_use())
                inner.append("m_rounds++;")
                inner.append(f"if (m_count {self.pick('>=', '<')} {limit}) break;")
                body.append("for (int round = 0; round < a_p; ++round)")
                body.append("{")
                body.extend("  " + line for x in inner for line in x.split("\n"))
                body.append("}")
            elif s == 9:
                body.extend(host_vector_use().split("\n"))
            else:
                body.append("m_count = 0;")
                body.append(call("Count"))
                body.append(f"m_k = m_count % {r.randint(2, 7)};")
        if not kernels:  # a class with no kernel is refused (rightly): give it one
            body.append(call("Map"))
        # The tail: reads what the kernels wrote, once they are done.
        tail = self.pick("m_total = m_sum + float(m_count);", "m_total = m_max * 2.0f + float(m_k);", "")
        if tail:
            body.append(tail)
        self.mode = self.rm.randint(0, 3)
        if self.rm.random() < 0.5:  # after the last kernel call: the next Run's pipelines are made for it
            body.append("m_mode = (m_mode + 1) & 3;")
        self.kernels, self.body = kernels, body

    def header(self):
        decls = "\n".join(f"  void {name}({params});" for name, params, _, _ in self.kernels)
        cell = f"struct {self.name}Cell\n{{\n  LiteMath::float4 lo, hi;\n}};\n\n" if self.cells else ""
        cells = f"  std::vector<{self.name}Cell> m_cells;\n" if self.cells else ""
        return f"""// Generated by test/differential/generate.py, seed {self.seed}: a random class in the subset
// CrossRT translates. Do not edit; regenerate.
#pragma once
#include "LiteMath.h"
#include "Specialize.h"

#include <cstdint>
#include <vector>

using LiteMath::InterlockedAdd;

{cell}class {self.name}
{{
public:
  {self.name}();
  virtual ~{self.name}() = default;
  virtual void CommitDeviceData() {{}}
  virtual void Run(int n, int a_p, float a_q);

  std::vector<float> m_a, m_b;
  std::vector<int> m_i;
  std::vector<int> m_found;
{cells}  std::vector<int> m_hist = std::vector<int>(8, 0);
  float m_bins[4] = {{0.0f, 1.0f, -2.0f, 0.5f}};
  float m_sum = 0.0f, m_max = -1000.0f, m_scale = 1.0f, m_total = 0.0f;
  int m_count = 0, m_k = 1, m_rounds = 0;
  CRT_SPECIALIZE int m_mode = {self.mode};

protected:
{decls}
}};
"""

    def source(self):
        cells = [f"  m_cells.resize({self.n});",
                 f"  for (int i = 0; i < {self.n}; ++i)", "  {",
                 "    m_cells[i].lo = LiteMath::float4(0.125f * float(i % 7), -1.0f, float(i % 3), 0.5f);",
                 "    m_cells[i].hi = LiteMath::float4(1.0f, 0.25f * float(i % 5), -0.5f, float(i % 4));", "  }"] if self.cells else []
        out = [f'// Generated by test/differential/generate.py, seed {self.seed}.',
               f'#include "diff_{self.seed}.h"', "", "#include <algorithm>", "#include <cmath>", "#include <utility>", "",
               f"{self.name}::{self.name}() : m_a({self.n}), m_b({self.n}), m_i({self.n})", "{",
               f"  m_found.reserve({self.n});",
               f"  for (int i = 0; i < {self.n}; ++i)", "  {",
               "    m_a[i] = 0.25f * float(i % 13) - 1.0f;", "    m_b[i] = float((i * 7) % 11);", "    m_i[i] = (i * 37) % 101;", "  }"] + cells + ["}", ""]
        for name, params, lines, args in self.kernels:
            if args == "2d":  # the lines are the loop nest
                out += [f"void {self.name}::{name}({params})", "{"] + ["  " + line for line in lines] + ["}", ""]
                continue
            before, after = self.around.get(name, ([], []))
            out += [f"void {self.name}::{name}({params})", "{"] + ["  " + line for line in before] + ["  for (int i = 0; i < n; ++i)", "  {"]
            out += ["    " + line for line in lines]
            out += ["  }"] + ["  " + line for line in after] + ["}", ""]
        out += [f"void {self.name}::Run(int n, int a_p, float a_q)", "{"]
        out += ["  " + s for s in self.body]
        out += ["}", ""]
        return "\n".join(out)

    def case(self):
        a_p = self.r.randint(1, 6)
        a_q = self.r.choice(["0.5f", "-1.5f", "3.0f"])
        return f"DIFFERENTIAL_CASE({self.name}, {self.seed}, {self.n}, {a_p}, {a_q})\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--first", type=int, default=1, help="first seed")
    ap.add_argument("--count", type=int, default=8, help="how many classes (seeds first .. first + count - 1)")
    ap.add_argument("--out", required=True, help="folder for the classes and cases.inc")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    cases = []
    for seed in range(args.first, args.first + args.count):
        g = Gen(seed)
        g.make()
        for path, text in ((f"diff_{seed}.h", g.header()), (f"diff_{seed}.cpp", g.source())):
            full = os.path.join(args.out, path)
            if not os.path.exists(full) or open(full).read() != text:  # unchanged files keep their times
                with open(full, "w") as f:
                    f.write(text)
        cases.append(g.case())
    text = "".join(cases)
    full = os.path.join(args.out, "cases.inc")
    if not os.path.exists(full) or open(full).read() != text:
        with open(full, "w") as f:
            f.write(text)


if __name__ == "__main__":
    main()
