#!/usr/bin/env python3
"""Compares two rig_calibrator output folders file by file.

Usage: compare_outputs.py A B [--tolerance T] [--exact NAME ...] [--ignore NAME ...]

Both folders must hold the same files (those named by --ignore left out).
With --tolerance 0 (the default) every file must be identical byte for byte.
With T > 0, text files are compared token by token (tokens separated by
white space and JSON punctuation): numbers x, y must satisfy
|x - y| <= T * max(1, |x|, |y|) (relative, or absolute below magnitude 1),
every other token must be equal, and the files named by --exact must still be
identical byte for byte. Prints, per file, "identical" or the largest scaled
difference; exits 1 on any mismatch.
"""
import argparse
import os
import re
import sys

TOKEN_SEPARATORS = re.compile(r'[\s,\[\]{}:"]+')


def as_number(token):
    try:
        return float(token)
    except ValueError:
        return None


def compare_text(path_a, path_b, tolerance):
    """(ok, largest scaled difference, message)."""
    try:
        with open(path_a, encoding='utf-8') as file_a, \
                open(path_b, encoding='utf-8') as file_b:
            tokens_a = [t for t in TOKEN_SEPARATORS.split(file_a.read()) if t]
            tokens_b = [t for t in TOKEN_SEPARATORS.split(file_b.read()) if t]
    except UnicodeDecodeError:
        return False, 0.0, 'binary file differs (compare text outputs)'
    if len(tokens_a) != len(tokens_b):
        return False, 0.0, '%d tokens against %d' % (len(tokens_a),
                                                     len(tokens_b))
    largest = 0.0
    for index, (a, b) in enumerate(zip(tokens_a, tokens_b)):
        if a == b:
            continue
        x, y = as_number(a), as_number(b)
        if x is None or y is None:
            return False, largest, 'token %d: %r against %r' % (index, a, b)
        scaled = abs(x - y) / max(1.0, abs(x), abs(y))
        largest = max(largest, scaled)
        if scaled > tolerance:
            return False, largest, 'token %d: %r against %r (%.3g > %.3g)' % (
                index, a, b, scaled, tolerance)
    return True, largest, ''


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('a')
    parser.add_argument('b')
    parser.add_argument('--tolerance', type=float, default=0.0)
    parser.add_argument('--exact', nargs='*', default=[])
    parser.add_argument('--ignore', nargs='*', default=[])
    args = parser.parse_args()

    names_a = set(os.listdir(args.a)) - set(args.ignore)
    names_b = set(os.listdir(args.b)) - set(args.ignore)
    ok = names_a == names_b
    if not ok:
        print('different files: only in %s: %s; only in %s: %s' %
              (args.a, sorted(names_a - names_b), args.b,
               sorted(names_b - names_a)))
    largest_overall = 0.0
    for name in sorted(names_a & names_b):
        path_a = os.path.join(args.a, name)
        path_b = os.path.join(args.b, name)
        with open(path_a, 'rb') as file_a, open(path_b, 'rb') as file_b:
            identical = file_a.read() == file_b.read()
        if identical:
            print('  %-34s identical' % name)
            continue
        if args.tolerance <= 0 or name in args.exact:
            print('  %-34s DIFFERS (must be identical)' % name)
            ok = False
            continue
        file_ok, largest, message = compare_text(path_a, path_b,
                                                 args.tolerance)
        largest_overall = max(largest_overall, largest)
        print('  %-34s %s, largest difference %.3g%s' %
              (name, 'equal within %.3g' % args.tolerance
               if file_ok else 'DIFFERS', largest,
               '' if file_ok else ': ' + message))
        ok = ok and file_ok
    print('largest difference over all files: %.3g' % largest_overall)
    return 0 if ok else 1


if __name__ == '__main__':
    sys.exit(main())
