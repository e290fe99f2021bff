#!/usr/bin/env python3
"""difftest.py: qcs against Hugs 98 on random programs (issue 20).

A seeded generator writes each program twice, once in qcs and once in
Haskell 98, from one tree of typed expressions in the subset the two
languages share: Reals, Bools, Strings, lists, tuples, functions of several
clauses with guards and `where`, `let`, `if`, `case`, lambdas, sections,
composition, comprehensions, ranges, infinite lists and planted `error`
leaves. qcs runs each program in a process of its own; the Haskell
programs run in batches, in one `runhugs` process each, every value forced
inside `try`. Values are compared exactly: qcs prints Reals as the
shortest decimal that reads back, the Haskell side prints them through
decodeFloat (Hugs's `show` gives 15 digits), and both become float.hex()
here. An error on either side is compared only as "an error here".

Where qcs means something else on purpose (lang/manual.md, Section 18
"qcs and Haskell"), the Haskell side calls a mirror (q_* below) that does
what qcs does, so only real deviations remain. Hugs's own faults with NaN
(`<=` and `>=` are True with a NaN side, isNaN is False) are mirrored
away too: the Haskell side compares Doubles through `<`, `>` and `==`,
which Hugs does by IEEE.

Usage: difftest.py [-n N] [--seed S] [--qcs PATH] [--runhugs PATH]
                   [--jobs J] [--show]
Prints "ok difftest/..." or "FAIL difftest/...: ..." lines (the suite
format of tests/run-all.sh) and, for every disagreement, both programs
and both answers. Exit status 1 on any disagreement.
"""
import argparse
import concurrent.futures
import math
import os
import random
import re
import shutil
import subprocess
import sys
import tempfile
import time

# ---- types ----------------------------------------------------------------
# 'D' Real/Double, 'B' Bool, 'S' String, ('L', t) list, ('T', a, b) pair.

D, B, S = 'D', 'B', 'S'


def L(t):
    return ('L', t)


def T(a, b):
    return ('T', a, b)


def hs_type(t):
    if t == D:
        return 'Double'
    if t == B:
        return 'Bool'
    if t == S:
        return 'String'
    if t[0] == 'L':
        return '[' + hs_type(t[1]) + ']'
    return '(' + hs_type(t[1]) + ', ' + hs_type(t[2]) + ')'


def hs_render(t):
    """The Haskell function that prints a value of type t as qcs would,
    with Doubles as D<mantissa>p<exponent>."""
    if t == D:
        return 'q_rD'
    if t == B:
        return 'q_rB'
    if t == S:
        return 'q_rS'
    if t[0] == 'L':
        return '(q_rL ' + hs_render(t[1]) + ')'
    return '(q_rT ' + hs_render(t[1]) + ' ' + hs_render(t[2]) + ')'


HS_PRELUDE = r'''
import Control.Exception

-- Printing, exactly: Doubles through decodeFloat. NaN is found by x /= x
-- and infinities by comparison (Hugs's isNaN and isInfinite are wrong).
q_rD :: Double -> String
q_rD x | x /= x = "NaN"
       | x == 1/0 = "Infinity"
       | x == -1/0 = "-Infinity"
       | x == 0 = if 1/x < 0 then "-0" else "0"
       | otherwise = let (m, e) = decodeFloat x in "D" ++ show m ++ "p" ++ show e
q_rB :: Bool -> String
q_rB b = if b then "True" else "False"
q_rS :: String -> String
q_rS s = "\"" ++ concatMap esc s ++ "\""
  where esc '"' = "\\\""
        esc '\\' = "\\\\"
        esc '\n' = "\\n"
        esc '\t' = "\\t"
        esc c = [c]
q_rL :: (a -> String) -> [a] -> String
q_rL r xs = "[" ++ go xs ++ "]"
  where go [] = ""
        go [y] = r y
        go (y:ys) = r y ++ ", " ++ go ys
q_rT :: (a -> String) -> (b -> String) -> (a, b) -> String
q_rT ra rb (a, b) = "(" ++ ra a ++ ", " ++ rb b ++ ")"

q_run :: Int -> String -> IO ()
q_run n s = do
  r <- try (evaluate (length s))
  case r of
    Left _ -> putStrLn ("#" ++ show n ++ " ERR")
    Right _ -> putStrLn ("#" ++ show n ++ " " ++ s)

-- IEEE comparisons (Hugs's <= and >= on Doubles are True with a NaN side).
q_le, q_ge :: Double -> Double -> Bool
q_le a b = a < b || a == b
q_ge a b = a > b || a == b

-- Mirrors of what qcs means on purpose (lang/manual.md, Section 18).
-- Ranges: element k is a + k*step; the end test is Haskell 98's.
q_range :: Double -> Double -> Double -> [Double]
q_range a step c
  | step == 0 = error "a range with step 0 never ends"
  | step > 0 = takeWhile (\x -> x < lim || x == lim) xs
  | otherwise = takeWhile (\x -> x > lim || x == lim) xs
  where lim = c + step / 2
        xs = [a + fromInteger k * step | k <- [0 ..]]
q_from :: Double -> Double -> [Double]
q_from a step = [a + fromInteger k * step | k <- [0 ..]]
-- foldl is strict in its accumulator.
q_foldl :: (b -> a -> b) -> b -> [a] -> b
q_foldl f z [] = z `seq` z
q_foldl f z (x:xs) = let z' = f z x in z' `seq` q_foldl f z' xs
-- sum starts from the first element.
q_sum :: [Double] -> Double
q_sum [] = 0
q_sum (x:xs) = q_foldl (+) x xs
-- min and max: the second argument only if it is strictly less (greater).
q_min, q_max :: Double -> Double -> Double
q_min a b = if b < a then b else a
q_max a b = if b > a then b else a
q_maximum, q_minimum :: [Double] -> Double
q_maximum (x:xs) = q_foldl q_max x xs
q_maximum [] = error "foldl1 of an empty list"
q_minimum (x:xs) = q_foldl q_min x xs
q_minimum [] = error "foldl1 of an empty list"
-- floor, ceiling, round (halves away from 0), truncate give Reals as C's
-- do: NaN and infinities pass through, a zero result keeps x's sign.
q_whole :: (Double -> Integer) -> Double -> Double
q_whole f x
  | x /= x || x == 1/0 || x == -1/0 = x
  | abs x >= 4503599627370496 = x
  | r == 0 && (x < 0 || 1/x < 0) = negate 0
  | otherwise = r
  where r = fromInteger (f x)
q_floor, q_ceiling, q_round, q_truncate :: Double -> Double
q_floor = q_whole floor
q_ceiling = q_whole ceiling
q_truncate = q_whole truncate
q_round = q_whole (\x -> let t = truncate x
                             d = x - fromInteger t
                         in if d >= 0.5 then t + 1 else if d <= -0.5 then t - 1 else t)
-- abs is C's fabs: abs (-0) is 0 (Haskell 98's abs keeps the -0).
q_abs :: Double -> Double
q_abs x = if x == 0 then 0 else abs x
-- Hugs's sqrt stops with an error on a negative number or NaN; C's
-- gives NaN.
q_sqrt :: Double -> Double
q_sqrt x = if x /= x || x < 0 then 0/0 else sqrt x
-- Strings are values, not lazy lists: ++ on Strings needs both sides.
infixr 5 `q_sapp`
q_sapp :: String -> String -> String
q_sapp a b = length a `seq` length b `seq` (a ++ b)
-- ^ is C's pow on two Reals: it needs its base even for an exponent 0.
infixr 8 `q_pow`
q_pow :: Double -> Integer -> Double
q_pow x n = x `seq` (x ^ n)
q_length :: [a] -> Double
q_length xs = fromIntegral (length xs)
'''


# ---- expressions ---------------------------------------------------------
# An expression is (qcs text, Haskell text, level): level is the precedence
# of its outermost operator (11 an atom, 10 an application, 6 a negation).

ATOM, APP = 11, 10
# op: (qcs, haskell, level, assoc) with assoc 'l', 'r' or 'n'.
OPS = {
    '+': ('+', '+', 6, 'l'), '-': ('-', '-', 6, 'l'),
    '*': ('*', '*', 7, 'l'), '/': ('/', '/', 7, 'l'),
    '^': ('^', '`q_pow`', 8, 'r'), '!!': ('!!', '!!', 9, 'l'),
    '.': ('.', '.', 9, 'r'), ':': (':', ':', 5, 'r'),
    '++': ('++', '++', 5, 'r'), '&&': ('&&', '&&', 3, 'r'),
    '||': ('||', '||', 2, 'r'),
    '==': ('==', '==', 4, 'n'), '/=': ('/=', '/=', 4, 'n'),
    '<': ('<', '<', 4, 'n'), '>': ('>', '>', 4, 'n'),
    '<=': ('<=', '<=', 4, 'n'), '>=': ('>=', '>=', 4, 'n'),
}


def par(e, need):
    q, h, lv = e
    if lv < need:
        return ('(' + q + ')', '(' + h + ')', ATOM)
    return e


def atom(e):
    return par(e, ATOM)


def binop(op, a, b):
    q, h, p, assoc = OPS[op]
    la = p if assoc == 'l' else p + 1
    ra = p if assoc == 'r' else p + 1
    a = par(a, la)
    b = par(b, ra)
    if b[2] == 6 and b[0].startswith('-') and p >= 6:
        b = atom(b)
    return (a[0] + ' ' + q + ' ' + b[0], a[1] + ' ' + h + ' ' + b[1], p)


def neg(a):
    a = par(a, 7)
    # Hugs reads - 0 as the literal 0, not as negate 0 (which is -0).
    h = '0.0' if a[1] == '0' else a[1]
    return ('- ' + a[0], '- ' + h, 6)


def app(fq, fh, *args):
    args = [atom(a) for a in args]
    return (' '.join([fq] + [a[0] for a in args]),
            ' '.join([fh] + [a[1] for a in args]), APP)


def same(text):
    return (text, text, ATOM)


def num_text(x):
    """A Real literal, written the same in both languages (no sign)."""
    if x == int(x) and abs(x) < 2 ** 53:
        return str(int(x))
    return repr(float(x))


class Gen:
    def __init__(self, rng, pid):
        self.rng = rng
        self.pid = pid
        self.names = 0
        self.funcs = []     # (name, [arg types], result type)
        self.defs_q = []
        self.defs_h = []

    def fresh(self, base='v'):
        self.names += 1
        return '%s%d_%d' % (base, self.pid, self.names)

    def chance(self, p):
        return self.rng.random() < p

    def pick(self, xs):
        return self.rng.choice(xs)

    # -- types
    def rtype(self, depth=2):
        r = self.rng.random()
        if depth <= 0 or r < 0.45:
            return D
        if r < 0.6:
            return B
        if r < 0.68:
            return S
        if r < 0.9:
            return L(self.rtype(depth - 1))
        return T(self.rtype(depth - 1), self.rtype(depth - 1))

    # -- literals
    def lit_num(self):
        return self.pick([0, 1, 2, 3, 0.5, 0.1, 0.25, 1.5, 2.5, 3.5, 10, 7,
                          0.3, 1e-3, 1e300, 4.75, 100, 1e16, 0.2])

    def lit(self, t):
        if t == D:
            x = self.lit_num()
            e = same(num_text(x))
            return neg(e) if self.chance(0.25) else e
        if t == B:
            return same(self.pick(['True', 'False']))
        if t == S:
            s = ''.join(self.pick('ab xyz01') for _ in range(self.rng.randrange(4)))
            if self.chance(0.1):
                s += self.pick(['\\n', '\\t', '\\"', '\\\\'])
            return same('"' + s + '"')
        if t[0] == 'L':
            return self.list_lit(t, 0)
        return self.tup(self.lit(t[1]), self.lit(t[2]))

    def tup(self, a, b):
        a, b = par(a, 1), par(b, 1)
        return ('(' + a[0] + ', ' + b[0] + ')', '(' + a[1] + ', ' + b[1] + ')', ATOM)

    def elem_text(self, e):
        # A cons as an element is bracketed: [(x : xs)] (issue 20).
        return e if e[2] > 5 else atom(e)

    def list_lit(self, t, depth):
        n = self.rng.randrange(4)
        items = [self.elem_text(self.expr(t[1], depth - 1)) for _ in range(n)]
        if not items:
            return ('[]', '([] :: ' + hs_type(t) + ')', ATOM)
        return ('[' + ', '.join(i[0] for i in items) + ']',
                '[' + ', '.join(i[1] for i in items) + ']', ATOM)

    # -- expressions of type t, with env: list of (name, type)
    def expr(self, t, depth, env=()):
        self.env = env
        return self._expr(t, depth, list(env))

    def var_of(self, t, env):
        vs = [n for n, ty in env if ty == t]
        return same(self.pick(vs)) if vs else None

    def _expr(self, t, depth, env):
        r = self.rng.random()
        if depth <= 0 or r < 0.12:
            v = self.var_of(t, env)
            if v and self.chance(0.6):
                return v
            return self.lit(t)
        if r < 0.15:
            return ('(error "bot")', '(error "bot" :: ' + hs_type(t) + ')', ATOM)
        if r < 0.28:
            return self.generic(t, depth, env)
        if t == D:
            return self.real(depth, env)
        if t == B:
            return self.boolean(depth, env)
        if t == S:
            return self.string(depth, env)
        if t[0] == 'L':
            return self.listx(t, depth, env)
        return self.pair(t, depth, env)

    def e(self, t, depth, env):
        return self._expr(t, depth, env)

    def generic(self, t, depth, env):
        """Forms that give a value of any type (if, let, case and lambdas
        bracketed: in qcs a case's alternatives run to the next `;`)."""
        return atom(self.generic1(t, depth, env))

    def generic1(self, t, depth, env):
        k = self.rng.randrange(9)
        d = depth - 1
        if k == 0:
            c = self.e(B, d, env)
            a, b = self.e(t, d, env), self.e(t, d, env)
            return ('if ' + c[0] + ' then ' + a[0] + ' else ' + b[0],
                    'if ' + c[1] + ' then ' + a[1] + ' else ' + b[1], 0)
        if k == 1:
            u = self.rtype(1)
            x = self.fresh()
            bound = self.e(u, d, env)
            env2 = env + [(x, u)]
            if self.chance(0.3):   # a local function
                f = self.fresh('g')
                y = self.fresh()
                fb = self.e(u, d, env + [(y, u)])
                body = self.e(t, d, env2 + [])
                use = app(f, f, bound)
                body = self.e(t, d, env2)
                return ('let ' + f + ' ' + y + ' = ' + fb[0] + '; ' + x + ' = ' + use[0] + ' in ' + body[0],
                        'let { ' + f + ' ' + y + ' = ' + fb[1] + '; ' + x + ' = ' + use[1] + ' } in ' + body[1], 0)
            body = self.e(t, d, env2)
            return ('let ' + x + ' = ' + bound[0] + ' in ' + body[0],
                    'let { ' + x + ' = ' + bound[1] + ' } in ' + body[1], 0)
        if k == 2:
            return self.case(t, d, env)
        if k == 3:   # a lambda applied
            u = self.rtype(1)
            x = self.fresh()
            body = self.e(t, d, env + [(x, u)])
            lam = ('\\' + x + ' -> ' + body[0], '\\' + x + ' -> ' + body[1], 0)
            return app(atom(lam)[0], atom(lam)[1], self.e(u, d, env))
        if k == 4:   # head of a list, or an index
            xs = self.e(L(t), d, env)
            if self.chance(0.5):
                return app('head', 'head', xs)
            return binop('!!', xs, same(str(self.rng.randrange(3))))
        if k == 5:   # fst / snd
            u = self.rtype(1)
            if self.chance(0.5):
                return app('fst', 'fst', self.e(T(t, u), d, env))
            return app('snd', 'snd', self.e(T(u, t), d, env))
        if k == 6:   # a top-level function of this program
            fs = [f for f in self.funcs if f[2] == t]
            if fs:
                name, args, _ = self.pick(fs)
                return app(name, name, *[self.e(a, d, env) for a in args])
            return self.define(t, d, env)
        if k == 7:   # foldr
            u = self.rtype(1)
            x, acc = self.fresh(), self.fresh()
            body = self.e(t, d, env + [(x, u), (acc, t)])
            lam = atom(('\\' + x + ' ' + acc + ' -> ' + body[0], '\\' + x + ' ' + acc + ' -> ' + body[1], 0))
            return app('foldr', 'foldr', lam, self.e(t, d, env), self.e(L(u), d, env))
        # strict foldl
        u = self.rtype(1)
        x, acc = self.fresh(), self.fresh()
        body = self.e(t, d, env + [(acc, t), (x, u)])
        lam = atom(('\\' + acc + ' ' + x + ' -> ' + body[0], '\\' + acc + ' ' + x + ' -> ' + body[1], 0))
        return app('foldl', 'q_foldl', lam, self.e(t, d, env), self.e(L(u), d, env))

    def case(self, t, d, env):
        u = self.pick([D, L(D), T(D, B), S])
        scrut = self.e(u, d, env)
        alts = []
        if u == D:
            for _ in range(self.rng.randrange(1, 3)):
                alts.append((num_text(self.pick([0, 1, 2, 0.5])), env))
            x = self.fresh()
            alts.append((x, env + [(x, D)]))
        elif u == S:
            alts.append(('"a"', env))
            alts.append(('_', env))
        elif u[0] == 'L':
            x, xs = self.fresh(), self.fresh()
            alts.append(('[]', env))
            if self.chance(0.5):
                y = self.fresh()
                alts.append(('[' + y + ']', env + [(y, D)]))
            alts.append(('(' + x + ' : ' + xs + ')', env + [(x, D), (xs, L(D))]))
        else:
            a, b = self.fresh(), self.fresh()
            alts.append(('(' + a + ', ' + b + ')', env + [(a, D), (b, B)]))
        qa, ha = [], []
        for i, (p, env2) in enumerate(alts):
            last = i == len(alts) - 1
            if self.chance(0.3):   # a guard; the last one falls through
                g = self.e(B, d - 1, env2)
                a1 = self.e(t, d - 1, env2)
                a2 = self.e(t, d - 1, env2)
                tail_q = ' | otherwise -> ' + a2[0] if last or self.chance(0.5) else ''
                tail_h = ' | otherwise -> ' + a2[1] if tail_q else ''
                qa.append(p + ' | ' + g[0] + ' -> ' + a1[0] + tail_q)
                ha.append(p + ' | ' + g[1] + ' -> ' + a1[1] + tail_h)
            else:
                a1 = self.e(t, d - 1, env2)
                qa.append(p + ' -> ' + a1[0])
                ha.append(p + ' -> ' + a1[1])
        return ('case ' + scrut[0] + ' of ' + '; '.join(qa),
                'case ' + scrut[1] + ' of { ' + '; '.join(ha) + ' }', 0)

    def define(self, t, d, env):
        """A new top-level function of 1 or 2 parameters, with clauses,
        guards and where; returns a call of it."""
        name = self.fresh('f')
        args = [self.rtype(1) for _ in range(self.rng.randrange(1, 3))]
        params = [self.fresh('x') for _ in args]
        penv = list(zip(params, args))
        clauses_q, clauses_h = [], []
        # a first clause with a pattern on the first parameter
        if self.chance(0.5):
            a0 = args[0]
            extra = []
            if a0 == D:
                p = num_text(self.pick([0, 1, 2]))
            elif a0 == S:
                p = '"a"'
            elif a0 == B:
                p = self.pick(['True', 'False'])
            elif a0[0] == 'L':
                if self.chance(0.5):
                    p = '[]'
                else:
                    h, tl = self.fresh(), self.fresh()
                    p = '(' + h + ' : ' + tl + ')'
                    extra = [(h, a0[1]), (tl, a0)]
            else:
                h, tl = self.fresh(), self.fresh()
                p = '(' + h + ', ' + tl + ')'
                extra = [(h, a0[1]), (tl, a0[2])]
            env1 = penv[1:] + extra
            pats = [p] + params[1:]
            body = self.e(t, d, env1)
            clauses_q.append(name + ' ' + ' '.join(pats) + ' = ' + body[0])
            clauses_h.append(name + ' ' + ' '.join(pats) + ' = ' + body[1])
        # a general clause, with guards and a where
        wq, wh, wenv = '', '', []
        if self.chance(0.4):
            w = self.fresh('w')
            wt = self.rtype(1)
            wb = self.e(wt, d, penv)
            wq = ' where ' + w + ' = ' + wb[0]
            wh = ' where { ' + w + ' = ' + wb[1] + ' }'
            wenv = [(w, wt)]
        env2 = penv + wenv
        if self.chance(0.4):
            g = self.e(B, d, env2)
            b1, b2 = self.e(t, d, env2), self.e(t, d, env2)
            clauses_q.append(name + ' ' + ' '.join(params) + ' | ' + g[0] + ' = ' + b1[0] +
                             ' | otherwise = ' + b2[0] + wq)
            clauses_h.append(name + ' ' + ' '.join(params) + ' | ' + g[1] + ' = ' + b1[1] +
                             ' | otherwise = ' + b2[1] + wh)
        else:
            b1 = self.e(t, d, env2)
            clauses_q.append(name + ' ' + ' '.join(params) + ' = ' + b1[0] + wq)
            clauses_h.append(name + ' ' + ' '.join(params) + ' = ' + b1[1] + wh)
        self.defs_q.append('\n'.join(clauses_q))
        self.defs_h.append(name + ' :: ' + ' -> '.join(hs_type(a) for a in args + [t]) +
                           '\n' + '\n'.join(clauses_h))
        self.funcs.append((name, args, t))
        return app(name, name, *[self.e(a, d, env) for a in args])

    def pred(self, u, d, env):
        """A function u -> Bool: a lambda or a section."""
        if u == D and self.chance(0.5):
            op = self.pick(['<', '>', '<=', '>=', '==', '/='])
            c = atom(self.e(D, d, env))
            if op in ('<=', '>='):
                hf = 'q_le' if op == '<=' else 'q_ge'
                if self.chance(0.5):
                    return ('(' + op + ' ' + c[0] + ')', '(`' + hf + '` ' + c[1] + ')', ATOM)
                return ('(' + c[0] + ' ' + op + ')', '(' + c[1] + ' `' + hf + '`)', ATOM)
            if self.chance(0.5):
                return ('(' + op + ' ' + c[0] + ')', '(' + op + ' ' + c[1] + ')', ATOM)
            return ('(' + c[0] + ' ' + op + ')', '(' + c[1] + ' ' + op + ')', ATOM)
        x = self.fresh()
        body = self.e(B, d, env + [(x, u)])
        return ('(\\' + x + ' -> ' + body[0] + ')', '(\\' + x + ' -> ' + body[1] + ')', ATOM)

    def fun(self, u, t, d, env):
        """A function u -> t: a lambda, a section or a composition."""
        if u == D and t == D and self.chance(0.5):
            op = self.pick(['+', '-', '*', '/'])
            c = atom(self.e(D, d, env))
            if op != '-' and self.chance(0.5):
                f = ('(' + op + ' ' + c[0] + ')', '(' + op + ' ' + c[1] + ')', ATOM)
            else:
                f = ('(' + c[0] + ' ' + op + ')', '(' + c[1] + ' ' + op + ')', ATOM)
            if self.chance(0.3):
                g = self.fun(D, D, d - 1, env)
                f = atom(binop('.', f, g))
            return f
        x = self.fresh()
        body = self.e(t, d, env + [(x, u)])
        return ('(\\' + x + ' -> ' + body[0] + ')', '(\\' + x + ' -> ' + body[1] + ')', ATOM)

    def real(self, depth, env):
        d = depth - 1
        k = self.rng.randrange(14)
        if k <= 3:
            return binop(self.pick(['+', '-', '*', '/']), self.e(D, d, env), self.e(D, d, env))
        if k == 4:
            return neg(self.e(D, d, env))
        if k == 5:   # mixed chains under a unary minus (issue 20)
            a, b, c = self.e(D, d - 1, env), self.e(D, d - 1, env), self.e(D, d - 1, env)
            inner = binop(self.pick(['*', '/']), a, binop('^', b, same(str(self.rng.randrange(3)))))
            if self.chance(0.5):
                inner = binop(self.pick(['*', '/']), inner, c)
            e = neg(inner)
            if self.chance(0.5):
                e = binop(self.pick(['+', '-']), e, self.e(D, d, env))
            return e
        if k == 6:
            return binop('^', self.e(D, d, env), same(str(self.rng.randrange(3))))
        if k == 7:
            f = self.pick([('abs', 'q_abs'), ('floor', 'q_floor'), ('ceiling', 'q_ceiling'),
                           ('round', 'q_round'), ('truncate', 'q_truncate'), ('sqrt', 'q_sqrt')])
            return app(f[0], f[1], self.e(D, d, env))
        if k == 8:
            f = self.pick([('min', 'q_min'), ('max', 'q_max')])
            return app(f[0], f[1], self.e(D, d, env), self.e(D, d, env))
        if k == 9:
            u = self.rtype(1)
            return app('length', 'q_length', self.e(L(u), d, env))
        if k == 10:
            f = self.pick([('sum', 'q_sum'), ('product', 'product'),
                           ('maximum', 'q_maximum'), ('minimum', 'q_minimum')])
            return app(f[0], f[1], self.e(L(D), d, env))
        if k == 11:
            return self.define(D, d, env)
        return self.generic(D, depth, env)

    def boolean(self, depth, env):
        d = depth - 1
        k = self.rng.randrange(10)
        if k <= 2:
            op = self.pick(['<', '>', '<=', '>=', '==', '/='])
            a, b = self.e(D, d, env), self.e(D, d, env)
            if op in ('<=', '>='):
                hf = 'q_le' if op == '<=' else 'q_ge'
                e = binop(op, a, b)
                a, b = atom(a), atom(b)
                return (e[0], hf + ' ' + a[1] + ' ' + b[1], 4)
            return binop(op, a, b)
        if k == 3:
            u = self.rtype(2)
            return binop(self.pick(['==', '/=']), self.e(u, d, env), self.e(u, d, env))
        if k == 4:
            return binop(self.pick(['&&', '||']), self.e(B, d, env), self.e(B, d, env))
        if k == 5:
            return app('not', 'not', self.e(B, d, env))
        if k == 6:
            u = self.rtype(1)
            f = self.pick(['any', 'all'])
            return app(f, f, self.pred(u, d, env), self.e(L(u), d, env))
        if k == 7:
            u = self.rtype(1)
            if self.chance(0.5):
                return app('null', 'null', self.e(L(u), d, env))
            return app('elem', 'elem', self.e(u, d, env), self.e(L(u), d, env))
        if k == 8:
            op = self.pick(['<', '>', '<=', '>=', '=='])
            return binop(op, self.e(S, d, env), self.e(S, d, env))
        return self.generic(B, depth, env)

    def string(self, depth, env):
        d = depth - 1
        if self.chance(0.5):
            return self.sapp(self.e(S, d, env), self.e(S, d, env))
        return self.generic(S, depth, env)

    def sapp(self, a, b):
        q, _, _ = binop('++', a, b)
        a, b = par(a, 6), par(b, 5)
        return (q, a[1] + ' `q_sapp` ' + b[1], 5)

    def pair(self, t, depth, env):
        d = depth - 1
        if self.chance(0.6):
            return self.tup(self.e(t[1], d, env), self.e(t[2], d, env))
        if self.chance(0.5):
            return app('head', 'head', app('zip', 'zip', self.e(L(t[1]), d, env), self.e(L(t[2]), d, env)))
        return self.generic(t, depth, env)

    def count(self, d, env):
        """A count for take, drop, replicate: a whole literal, or a length."""
        if self.chance(0.8):
            return same(str(self.rng.randrange(5)))
        u = self.rtype(1)
        e = self.e(L(u), d, env)
        return ('length ' + atom(e)[0], 'length ' + atom(e)[1], APP)

    def infinite(self, t, d, env):
        """An infinite list of t (only ever consumed by take, zip, !!)."""
        k = self.rng.randrange(5)
        if t == D and k <= 1:
            a = self.lit_num()
            if k == 0:
                return ('[' + num_text(a) + ' ..]', '(q_from ' + num_text(a) + ' 1)', ATOM)
            b = self.pick([0, 1, 2, 0.5, 0.1, -1, 3])
            bq = num_text(abs(b)) if b >= 0 else '- ' + num_text(-b)
            bh = num_text(abs(b)) if b >= 0 else '(' + str(b) + ')'
            return ('[' + num_text(a) + ', ' + bq + ' ..]',
                    '(q_from ' + num_text(a) + ' (' + bh + ' - ' + num_text(a) + '))', ATOM)
        if k == 2:
            return app('repeat', 'repeat', self.e(t, d, env))
        if k == 3:
            return app('iterate', 'iterate', self.fun(t, t, d, env), self.e(t, d, env))
        # a finite list then an error: take must not go past it
        xs = self.e(L(t), d, env)
        return binop('++', xs, app('error', 'error', same('"bot"')))

    def listx(self, t, depth, env):
        d = depth - 1
        u = t[1]
        k = self.rng.randrange(22)
        if k <= 1:
            return self.list_lit(t, depth)
        if k == 2:
            return binop(':', self.e(u, d, env), self.e(t, d, env))
        if k == 3:   # Clean's tail form [x, y : rest]
            items = [self.elem_text(self.e(u, d, env)) for _ in range(self.rng.randrange(1, 3))]
            rest = self.e(t, d, env)
            rq = rest
            if rest[2] <= 4:
                rq = atom(rest)
            q = '[' + ', '.join(i[0] for i in items) + ' : ' + rq[0] + ']'
            h = '(' + ' : '.join(atom(i)[1] if i[2] <= 5 else i[1] for i in items) + ' : ' + par(rest, 5)[1] + ')'
            return (q, h, ATOM)
        if k == 4:
            return binop('++', self.e(t, d, env), self.e(t, d, env))
        if k == 5:
            v = self.pick([D, B, L(D), T(D, D)])
            return app('map', 'map', self.fun(v, u, d, env), self.e(L(v), d, env))
        if k == 6:
            return app('filter', 'filter', self.pred(u, d, env), self.e(t, d, env))
        if k == 7:
            f = self.pick(['take', 'drop'])
            return app(f, f, self.count(d, env), self.e(t, d, env))
        if k == 8:
            return app('take', 'take', self.count(d, env), self.infinite(u, d, env))
        if k == 9:
            f = self.pick(['takeWhile', 'dropWhile'])
            return app(f, f, self.pred(u, d, env), self.e(t, d, env))
        if k == 10:
            f = self.pick(['reverse', 'tail'])
            return app(f, f, self.e(t, d, env))
        if k == 11:
            return app('replicate', 'replicate', self.count(d, env), self.e(u, d, env))
        if k == 12:
            return app('concat', 'concat', self.e(L(t), d, env))
        if k == 13 or k == 14:   # comprehension
            v = self.pick([D, B, T(D, B)])
            if v[0] == 'T' and self.chance(0.7):
                a, b = self.fresh(), self.fresh()
                pat = '(' + a + ', ' + b + ')'
                env2 = env + [(a, D), (b, B)]
            else:
                x = self.fresh()
                pat, env2 = x, env + [(x, v)]
            src = self.e(L(v), d, env)
            quals_q, quals_h = [pat + ' <- ' + src[0]], [pat + ' <- ' + src[1]]
            if self.chance(0.4):
                y = self.fresh()
                src2 = self.e(L(D), d - 1, env2)
                quals_q.append(y + ' <- ' + src2[0])
                quals_h.append(y + ' <- ' + src2[1])
                env2 = env2 + [(y, D)]
            if self.chance(0.6):
                c = self.e(B, d, env2)
                quals_q.append(c[0])
                quals_h.append(c[1])
            head = par(self.e(u, d, env2), 1)
            return ('[' + head[0] + ' | ' + ', '.join(quals_q) + ']',
                    '[' + head[1] + ' | ' + ', '.join(quals_h) + ']', ATOM)
        if u == D and k <= 17:   # ranges
            # (a literal start: a computed one may be -1e300, and the
            # range then never reaches its end)
            if True:
                x = self.pick([0.5, 0.1, 1.5, 2.5]) if self.chance(0.3) else self.rng.randrange(-3, 8)
                a = same(num_text(x)) if x >= 0 else neg(same(num_text(-x)))
            c = same(num_text(self.pick([0, 1, 2.5, 3.5, 5, 8, 10, 41, 0.3, 1])))
            if self.chance(0.5):
                return ('[' + a[0] + ' .. ' + c[0] + ']',
                        'q_range ' + atom(a)[1] + ' 1 ' + c[1], APP)
            step = self.pick([1, 2, 3, 4, 0.5, 0.25, 0.1, -1, -2, 0.3])
            if a[2] == ATOM and re.fullmatch(r'[0-9.e]+', a[0]):
                av = float(a[0])
            else:
                av = 0.0
                a = same('0')
            b = av + step
            bt = num_text(b) if b >= 0 else '- ' + num_text(-b)
            bh = num_text(b) if b >= 0 else '(' + repr(b) + ')'
            return ('[' + a[0] + ', ' + bt + ' .. ' + c[0] + ']',
                    'q_range ' + a[1] + ' (' + bh + ' - ' + a[1] + ') ' + c[1], APP)
        if u[0] == 'T' and k <= 19:
            return app('zip', 'zip', self.e(L(u[1]), d, env),
                       self.infinite(u[2], d, env) if self.chance(0.3) else self.e(L(u[2]), d, env))
        if k <= 19:
            v = self.pick([D, B])
            w = self.pick([D, B])
            x, y = self.fresh(), self.fresh()
            body = self.e(u, d, env + [(x, v), (y, w)])
            lam = ('(\\' + x + ' ' + y + ' -> ' + body[0] + ')', '(\\' + x + ' ' + y + ' -> ' + body[1] + ')', ATOM)
            return app('zipWith', 'zipWith', lam, self.e(L(v), d, env), self.e(L(w), d, env))
        return self.generic(t, depth, env)


def make_program(seed, pid):
    rng = random.Random(seed * 1000003 + pid)
    g = Gen(rng, pid)
    t = g.rtype(2)
    body = g.expr(t, rng.randrange(2, 5))
    qsrc = '\n'.join(g.defs_q + [body[0]]) + '\n'
    hdefs = '\n'.join(g.defs_h)
    hmain = 'p%d :: %s\np%d = %s\n' % (pid, hs_type(t), pid, body[1])
    return qsrc, (hdefs + '\n' if hdefs else '') + hmain, t


# ---- reading the answers --------------------------------------------------

TOKEN = re.compile(r'\s*(?:(D-?\d+p-?\d+)|(-?Infinity|NaN|-?[0-9][0-9.]*(?:e[-+]?\d+)?)'
                   r'|("(?:[^"\\]|\\.)*")|(True|False)|([\[\](),]))')


def canon(text):
    """A printed value as a canonical string, Reals as float.hex()."""
    out = []
    pos = 0
    text = text.strip()
    while pos < len(text):
        m = TOKEN.match(text, pos)
        if not m:
            return 'UNREADABLE ' + text
        pos = m.end()
        if m.group(1):
            mant, ex = m.group(1)[1:].split('p')
            out.append(math.ldexp(int(mant), int(ex)).hex())
        elif m.group(2):
            s = m.group(2)
            x = float('nan') if s == 'NaN' else float(s.replace('Infinity', 'inf'))
            out.append('nan' if x != x else x.hex())
        else:
            out.append(m.group(0).strip())
    return ' '.join(out)


def run_qcs(qcs, path):
    try:
        p = subprocess.run([qcs, path], capture_output=True, text=True, timeout=20)
    except subprocess.TimeoutExpired:
        return 'TIMEOUT'
    if p.returncode != 0:
        return 'ERR' if 'error' in p.stderr else 'CRASH %d: %s' % (p.returncode, p.stderr[:200])
    return canon(p.stdout)


def run_hugs(runhugs, path, ids):
    try:
        p = subprocess.run([runhugs, path], capture_output=True, text=True, timeout=120)
    except subprocess.TimeoutExpired:
        return None, 'runhugs timed out'
    got = {}
    for line in p.stdout.splitlines():
        m = re.match(r'#(\d+) (.*)$', line)
        if m:
            got[int(m.group(1))] = 'ERR' if m.group(2) == 'ERR' else canon(m.group(2))
    if p.returncode != 0 or len(got) != len(ids):
        return got, 'runhugs: status %d: %s' % (p.returncode, (p.stderr or p.stdout)[-600:])
    return got, None


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('-n', type=int, default=300)
    ap.add_argument('--seed', type=int, default=1)
    ap.add_argument('--qcs', default='./qcs')
    ap.add_argument('--runhugs', default='runhugs')
    ap.add_argument('--jobs', type=int, default=os.cpu_count() or 2)
    ap.add_argument('--batch', type=int, default=250)
    ap.add_argument('--show', action='store_true', help='print every program')
    a = ap.parse_args()
    if not shutil.which(a.runhugs):
        print('FAIL difftest: runhugs not found (Debian package hugs; make deps installs it)')
        return 1
    t0 = time.time()
    tmp = tempfile.mkdtemp(prefix='difftest.')
    progs = [make_program(a.seed, i) for i in range(a.n)]
    qpaths = []
    for i, (q, _, _) in enumerate(progs):
        path = os.path.join(tmp, 'p%d.qcs' % i)
        with open(path, 'w') as f:
            f.write(q)
        qpaths.append(path)
    batches = [list(range(i, min(i + a.batch, a.n))) for i in range(0, a.n, a.batch)]
    hpaths = []
    for bi, ids in enumerate(batches):
        path = os.path.join(tmp, 'B%d.hs' % bi)
        with open(path, 'w') as f:
            f.write('module Main where\n' + HS_PRELUDE + '\n')
            for i in ids:
                f.write(progs[i][1] + '\n')
            f.write('main :: IO ()\nmain = do\n')
            for i in ids:
                f.write('  q_run %d (%s p%d)\n' % (i, hs_render(progs[i][2]), i))
        hpaths.append(path)
    hs, qs = {}, [None] * a.n
    problems = []
    with concurrent.futures.ThreadPoolExecutor(a.jobs) as ex:
        hfut = [ex.submit(run_hugs, a.runhugs, p, ids) for p, ids in zip(hpaths, batches)]
        qfut = [ex.submit(run_qcs, a.qcs, p) for p in qpaths]
        for i, f in enumerate(qfut):
            qs[i] = f.result()
        for (got, err), path in zip((f.result() for f in hfut), hpaths):
            hs.update(got or {})
            if err:
                problems.append('%s: %s' % (path, err))
    bad = []
    for i in range(a.n):
        h = hs.get(i, 'MISSING')
        if qs[i] != h:
            bad.append(i)
    for i in bad:
        q, h, t = progs[i]
        print('--- program %d (seed %d), type %s' % (i, a.seed, hs_type(t)))
        print('qcs:\n' + q.rstrip())
        print('Haskell:\n' + h.rstrip())
        print('qcs gives:     ' + qs[i])
        print('Haskell gives: ' + hs.get(i, 'MISSING'))
    if a.show:
        for i in range(a.n):
            print('--- %d\n%s=> %s' % (i, progs[i][0], qs[i]))
    errs = sum(1 for i in range(a.n) if qs[i] == 'ERR')
    dt = time.time() - t0
    for p in problems:
        print('FAIL difftest: ' + p)
    name = 'difftest/seed-%d-n-%d' % (a.seed, a.n)
    if bad:
        print('FAIL %s: %d of %d programs disagree with Hugs (%d errors on the qcs side, %.1f s)'
              % (name, len(bad), a.n, errs, dt))
    else:
        print('ok %s: %d programs agree with Hugs (%d of them errors, %.1f s)'
              % (name, a.n, errs, dt))
    if not problems and not bad:
        shutil.rmtree(tmp)
    else:
        print('programs kept in ' + tmp)
    return 1 if bad or problems else 0


if __name__ == '__main__':
    sys.exit(main())
