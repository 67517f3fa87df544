#!/usr/bin/env python3
"""Lists the functions in src/ (and apps/) longer than a limit, the longest first.

  python3 tools/long_functions.py [--max 100] [PATH ...]

A function's length is counted from the line of its name to the line of its closing brace,
blank and comment lines included. Prints one line a function, `file:line: N lines: name`, and
nothing when every function is within the limit; exits 1 when it printed anything.

The C++ is read with a small scanner, not a compiler: comments, strings and character literals
are skipped, and a function is a `{` at namespace or class scope that follows a parameter list.
Lambdas and local classes count toward the function that holds them.
"""
import argparse
import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SOURCE_EXTENSIONS = ('.cc', '.h', '.cpp', '.hpp')


def blank_out(text):
    """The text with comments, strings and character literals replaced by spaces (newlines
    kept, so that line numbers stay)."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith('//', i):
            j = text.find('\n', i)
            j = n if j < 0 else j
            out.append(' ' * (j - i))
            i = j
        elif text.startswith('/*', i):
            j = text.find('*/', i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r'[^\n]', ' ', text[i:j]))
            i = j
        elif c == 'R' and text.startswith('R"', i) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == '_')):
            m = re.match(r'R"([^(\s]*)\(', text[i:])
            if not m:
                out.append(c)
                i += 1
                continue
            end = text.find(')' + m.group(1) + '"', i)
            j = n if end < 0 else end + len(m.group(1)) + 2
            out.append(re.sub(r'[^\n]', ' ', text[i:j]))
            i = j
        elif c in '"\'':
            # A digit separator (1'000) is not a character literal.
            if c == "'" and i > 0 and text[i - 1].isalnum() and i + 1 < n and text[i + 1].isalnum():
                out.append(' ')
                i += 1
                continue
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == '\\' else 1
            j = min(j + 1, n)
            out.append(re.sub(r'[^\n]', ' ', text[i:j]))
            i = j
        else:
            out.append(c)
            i += 1
    return ''.join(out)


NOT_FUNCTION = re.compile(r'\b(class|struct|union|enum|namespace|extern)\b[^()]*$')
CONTROL = re.compile(r'\b(if|for|while|switch|catch)\s*$')


def functions(text):
    """(name, first line, last line) of each function body at namespace or class scope."""
    code = blank_out(text)
    line_of = [0] * (len(code) + 1)
    line = 1
    for k, ch in enumerate(code):
        line_of[k] = line
        if ch == '\n':
            line += 1
    found = []
    # A stack of scopes: 'scope' (namespace, class, extern block) or 'other'.
    stack = []
    statement_start = 0
    i = 0
    while i < len(code):
        ch = code[i]
        if ch == '{':
            head = code[statement_start:i]
            in_scope = all(s == 'scope' for s in stack)
            stripped = re.sub(r'\s+', ' ', head).strip()
            if in_scope and NOT_FUNCTION.search(stripped) is None and ')' in stripped and \
                    not stripped.endswith('=') and not CONTROL.search(stripped.split('(')[0]):
                # A function body: find its closing brace.
                depth, j = 1, i + 1
                while j < len(code) and depth:
                    if code[j] == '{':
                        depth += 1
                    elif code[j] == '}':
                        depth -= 1
                    j += 1
                name_match = re.search(r'([~\w:<>]+(?:operator\s*[^\s(]+)?)\s*\(', stripped)
                name = name_match.group(1) if name_match else stripped[:40]
                first_char = statement_start + len(head) - len(head.lstrip())
                found.append((name, line_of[first_char], line_of[j - 1]))
                i = j
                statement_start = j
                continue
            stack.append('scope' if in_scope and NOT_FUNCTION.search(stripped) else 'other')
            statement_start = i + 1
        elif ch == '}':
            if stack:
                stack.pop()
            statement_start = i + 1
        elif ch == ';':
            statement_start = i + 1
        elif ch == ':' and re.search(r'\b(public|private|protected)\s*$', code[statement_start:i]):
            statement_start = i + 1
        elif ch == '#':
            # A preprocessor line ends no statement but is not part of one either.
            j = code.find('\n', i)
            j = len(code) if j < 0 else j
            if code[statement_start:i].strip() == '':
                statement_start = j + 1
            i = j
            continue
        i += 1
    return found


def main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('paths', nargs='*', default=['src', 'apps'],
                        help='files or folders to read, relative to the repository (default: src apps)')
    parser.add_argument('--max', type=int, default=100, help='the longest a function may be, in lines')
    args = parser.parse_args()
    long_ones = []
    for path in args.paths:
        full = path if os.path.isabs(path) else os.path.join(ROOT, path)
        if not os.path.exists(full):
            print(f'long_functions: no such file or folder: {path}', file=sys.stderr)
            return 2
        files = [full] if os.path.isfile(full) else [
            os.path.join(d, f) for d, _, fs in os.walk(full) for f in fs if f.endswith(SOURCE_EXTENSIONS)]
        for f in sorted(files):
            with open(f, encoding='utf-8', errors='replace') as handle:
                text = handle.read()
            for name, first, last in functions(text):
                length = last - first + 1
                if length > args.max:
                    long_ones.append((length, os.path.relpath(f, ROOT), first, name))
    for length, f, first, name in sorted(long_ones, key=lambda x: (-x[0], x[1], x[2])):
        print(f'{f}:{first}: {length} lines: {name}')
    return 1 if long_ones else 0


if __name__ == '__main__':
    sys.exit(main())
