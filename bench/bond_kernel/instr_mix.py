#!/usr/bin/env python3
"""Dynamic instruction mix of one function from a callgrind profile taken with
--dump-instr=yes: each instruction's execution count (self cost, calls
excluded) joined with the binary's disassembly (objdump), summed by kind.

    instr_mix.py PROFILE BINARY FUNCTION_SUBSTRING [--per N] [--site FILE]

--per N divides the counts by N (e.g. the bond evaluations). Prints the
classes (FP arithmetic by kind, loads/stores/moves, compares and branches,
integer and other) and the counts per source line: the innermost line
(objdump -l), or with --site FILE the line of FILE that the instruction
was inlined into (its inline chain, addr2line -i), e.g. the line of
evaluate_bond that called an inlined helper.
"""
import re
import subprocess
import sys
from collections import defaultdict


def parse_profile(path, fn_sub):
    counts = defaultdict(int)  # address -> Ir (self)
    cur_ob = cur_fn = None
    in_fn = False
    last_addr = 0
    skip_next = False
    names = {}  # compressed name ids
    with open(path) as f:
        for line in f:
            line = line.rstrip('\n')
            if not line:
                continue
            m = re.match(r'^(ob|fl|fi|fe|fn|cob|cfi|cfl|cfn)=(\((\d+)\))?\s*(.*)$', line)
            if m:
                key, _, ident, name = m.groups()
                if ident and name:
                    names[(key[-2:] if key.startswith('c') else key, ident)] = name
                if key == 'fn':
                    full = name if name else names.get(('fn', ident), '')
                    in_fn = fn_sub in full
                continue
            if line.startswith('calls='):
                skip_next = True
                continue
            if not (line[0].isdigit() or line[0] in '+-*0'):
                continue
            parts = line.split()
            a = parts[0]
            if a == '*':
                addr = last_addr
            elif a.startswith('+'):
                addr = last_addr + int(a[1:], 0)
            elif a.startswith('-'):
                addr = last_addr - int(a[1:], 0)
            else:
                addr = int(a, 0)
            last_addr = addr
            if skip_next:
                skip_next = False
                continue
            if in_fn and len(parts) >= 3:
                counts[addr] += int(parts[2])
    return counts


def disassemble(binary, addrs):
    lo, hi = min(addrs), max(addrs) + 16
    out = subprocess.run(['objdump', '-d', '-l', '--no-show-raw-insn', '-C',
                          f'--start-address={lo:#x}', f'--stop-address={hi:#x}', binary],
                         capture_output=True, text=True).stdout
    insn, src = {}, {}
    where = '?'
    for line in out.splitlines():
        m = re.match(r'^(/\S+):(\d+)', line)
        if m:
            where = f'{m.group(1).split("/")[-1]}:{m.group(2)}'
            continue
        m = re.match(r'^\s+([0-9a-f]+):\s+(\S+)\s*(.*)$', line)
        if m:
            a = int(m.group(1), 16)
            insn[a] = (m.group(2), m.group(3))
            src[a] = where
    return insn, src


def call_sites(binary, addrs, site_file):
    """address -> 'file:line' of the first frame of the inline chain in site_file."""
    out = subprocess.run(['addr2line', '-i', '-a', '-e', binary],
                         input=''.join(f'{a:#x}\n' for a in addrs), capture_output=True,
                         text=True).stdout
    sites, cur = {}, None
    for line in out.splitlines():
        if line.startswith('0x'):
            cur = int(line, 16)
            sites[cur] = '?'
        elif cur is not None and sites[cur] == '?' and site_file in line:
            sites[cur] = line.split(' (')[0].split('/')[-1]
    return sites


def kind(op, args):
    # VEX forms (-march=x86-64-v3): vfmadd231sd etc. are fused multiply-adds
    # (2 flops); the other v-prefixed ones are the SSE2 ones in new dress.
    if op.startswith(('vfmadd', 'vfmsub', 'vfnmadd', 'vfnmsub')):
        return 'fp fma (packed)' if op.endswith('pd') else 'fp fma'
    if op.startswith('v') and not op.startswith('vzero'):
        op = op[1:]
    fp = {'addsd': 'fp add/sub', 'subsd': 'fp add/sub', 'mulsd': 'fp mul', 'divsd': 'fp div',
          'sqrtsd': 'fp sqrt', 'addpd': 'fp add/sub (packed)', 'subpd': 'fp add/sub (packed)',
          'mulpd': 'fp mul (packed)', 'divpd': 'fp div (packed)'}
    if op in fp:
        return fp[op]
    if op.startswith(('ucomisd', 'comisd', 'cmp', 'test')):
        return 'compare'
    if op.startswith('j'):
        return 'branch'
    if op in ('xorpd', 'andpd', 'andnpd', 'orpd', 'pxor'):
        return 'sign/abs/zero (bit ops)'
    if op.startswith(('mov', 'unpck', 'shufpd', 'cvt', 'lea', 'push', 'pop')):
        mem = '(' in args
        if op.startswith('lea'):
            return 'address (lea)'
        if mem and args.split(',')[-1].strip().startswith(('0x', '-0x', '(')) and '(' in args.split(',')[-1]:
            return 'store'
        if mem:
            return 'load'
        return 'register move/shuffle'
    return 'other'


def main():
    prof, binary, fn = sys.argv[1:4]
    per = float(sys.argv[sys.argv.index('--per') + 1]) if '--per' in sys.argv else 1.0
    counts = parse_profile(prof, fn)
    if not counts:
        sys.exit(f'{prof}: no instruction counts for a function matching {fn!r} (--dump-instr=yes?)')
    # PIE: callgrind's addresses are the file's own for the main executable.
    insn, src = disassemble(binary, list(counts))
    if '--site' in sys.argv:
        src = call_sites(binary, sorted(counts), sys.argv[sys.argv.index('--site') + 1])
    classes, lines = defaultdict(float), defaultdict(float)
    total = 0.0
    missing = 0
    for a, c in counts.items():
        total += c
        if a not in insn:
            missing += c
            continue
        op, args = insn[a]
        classes[kind(op, args)] += c
        lines[src.get(a, '?')] += c
    print(f'{fn}: {total / per:.1f} instructions per unit ({total:.0f} in all; '
          f'{missing / per:.1f} per unit not found in the disassembly)')
    for k, v in sorted(classes.items(), key=lambda kv: -kv[1]):
        print(f'  {k:28s} {v / per:8.1f}  ({100 * v / total:4.1f} %)')
    print('by source line (top 40):')
    for k, v in sorted(lines.items(), key=lambda kv: -kv[1])[:40]:
        print(f'  {k:40s} {v / per:8.1f}')


if __name__ == '__main__':
    main()
