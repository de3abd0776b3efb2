#include "cal/calcomp.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>

namespace dayflux::cal {
namespace {

double Eval(Context &cx, const std::string &e, const Channels *ch = nullptr) {
    return cx.Compile(e, FileLoc{"expr", 1}).Evaluate(cx, ch);
}

std::string ErrorOf(const std::function<void()> &f) {
    try {
        f();
    } catch (const UserError &e) {
        return e.what();
    }
    return "";
}

TEST(Calcomp, ArithmeticAndPrecedenceAsRadiance) {
    Context cx;
    EXPECT_EQ(Eval(cx, "1 + 2*3 - 4/2"), 5);
    EXPECT_EQ(Eval(cx, "2^3^2"), 512);  // right associative
    EXPECT_EQ(Eval(cx, "-2^2"), 4);     // unary minus binds tighter than ^ in calcomp
    EXPECT_EQ(Eval(cx, "(1+2)*-(3)"), -9);
    EXPECT_EQ(Eval(cx, "1.5e2 + .5 + 2E-1"), 150.7);
    EXPECT_EQ(Eval(cx, "7/0*1 + 1"), 1);  // division by zero gives 0
}

TEST(Calcomp, DefinitionsFunctionsAndRecursion) {
    Context cx;
    cx.Load(
        "{ comments { nest } } a = 2; b : a*3; f(x, y) = x*10 + y;\n"
        "fact(n) = if(n - .5, n*fact(n-1), 1);  g(h, x) = h(x) + 1;  sq2(x) = x*x;",
        FileLoc{"t.cal", 1});
    EXPECT_EQ(Eval(cx, "b"), 6);
    EXPECT_EQ(Eval(cx, "f(1, 2)"), 12);
    EXPECT_EQ(Eval(cx, "fact(6)"), 720);
    EXPECT_EQ(Eval(cx, "g(sq2, 3)"), 10);  // a function passed as an argument
    cx.Set("a", 5);
    EXPECT_EQ(Eval(cx, "a"), 5);
}

TEST(Calcomp, IfAndSelectEvaluateLazily) {
    Context cx;
    cx.Load("boom(x) = boom(x+1); safe = if(1, 7, boom(0));", FileLoc{"t.cal", 1});
    EXPECT_EQ(Eval(cx, "safe"), 7);
    EXPECT_EQ(Eval(cx, "select(2, boom(0), 8, boom(1))"), 8);
    EXPECT_EQ(Eval(cx, "select(0, 4, 5, 6)"), 3);  // select(0, ...) counts the choices
    EXPECT_EQ(Eval(cx, "max(3, 9, 2) + min(3, 9, 2)"), 11);
}

TEST(Calcomp, ChannelsGiveRayVariables) {
    Context cx;
    cx.Load("Dx = $1; Dy = $2; Dz = $3; up = if(Dz, 1, -1);", FileLoc{"t.cal", 1});
    ChannelArray ray({0.6, 0, -0.8});
    EXPECT_EQ(Eval(cx, "up", &ray), -1);
    EXPECT_DOUBLE_EQ(Eval(cx, "atan2(Dx, Dy)", &ray), M_PI / 2);
}

// in(n) is rcalc's alone: elsewhere an undefined function; with AllowInFunction, $n for n != 0
// (rounded as RADIANCE's (int)(n + .5)) and the channels' count for 0, and a definition of in()
// still wins.
TEST(Calcomp, InIsRcalcsColumnFunction) {
    class Columns : public ChannelArray {
      public:
        using ChannelArray::ChannelArray;
        int Count() const override { return 2; }
    };
    const Columns record({5, 6});
    Context plain;
    EXPECT_NE(ErrorOf([&] { Eval(plain, "in(1)", &record); }).find("undefined function 'in'"),
              std::string::npos);
    Context cx;
    cx.AllowInFunction();
    EXPECT_EQ(Eval(cx, "in(1)", &record), 5);
    EXPECT_EQ(Eval(cx, "in(1.6)", &record), 6);
    EXPECT_EQ(Eval(cx, "in(0) + in(-.4)", &record), 4);
    EXPECT_NE(ErrorOf([&] { Eval(cx, "in(1e30)", &record); }).find("illegal channel number"),
              std::string::npos);
    cx.Load("in(n) = 10 * n;", FileLoc{"t.cal", 1});
    EXPECT_EQ(Eval(cx, "in(1)", &record), 10);
}

TEST(Calcomp, ConstantsAreReducedAsRadianceDoes) {
    // RADIANCE turns x/c into x*(1/c): the same last bit as RADIANCE matters at bin boundaries.
    Context cx;
    cx.Load("x = $1;", FileLoc{"t.cal", 1});
    ChannelArray v({0.7});
    EXPECT_EQ(Eval(cx, "x/3", &v), 0.7 * (1. / 3.));
    EXPECT_EQ(Eval(cx, "x*0 + 2^0 + x^1", &v), 0.7 + 1);
    EXPECT_EQ(Eval(cx, "x*0 + 2^0"), 1);  // folded: x is never evaluated, so no ray is needed
}

// RADIANCE's libfunc() and epow(): a NaN or infinite result of a library function or a power is
// a domain or range error, warned of and 0 (issue 41: NaN bins and patterns). The specialised
// evaluation and the GLSL agree (their tests).
TEST(Calcomp, DomainAndRangeErrorsGiveZeroAsRadianceDoes) {
    Context cx;
    cx.Load("x = $1;", FileLoc{"t.cal", 1});
    ChannelArray v({-1});
    testing::internal::CaptureStderr();
    EXPECT_EQ(Eval(cx, "sqrt(x)", &v), 0);
    EXPECT_EQ(Eval(cx, "sqrt(x) + 1", &v), 1);
    EXPECT_EQ(Eval(cx, "log(x + 1)", &v), 0);      // -inf: a range error
    EXPECT_EQ(Eval(cx, "exp(-1000 * x)", &v), 0);  // inf
    EXPECT_EQ(Eval(cx, "asin(2 * x)", &v), 0);
    EXPECT_EQ(Eval(cx, "(8 * x)^(1/3)", &v), 0);
    EXPECT_EQ(Eval(cx, "sqrt(-4)"), 0);  // folded where it is read
    EXPECT_EQ(Eval(cx, "sqrt(-x) + (-x)^.5 + exp(x)", &v), 2 + std::exp(-1));
    const std::string said = testing::internal::GetCapturedStderr();
    for (const char *w : {"sqrt: domain error (0 used, as RADIANCE does)", "log: range error",
                          "exp: range error", "asin: domain error", "power: domain error"})
        EXPECT_NE(said.find(w), std::string::npos) << w << " in " << said;
    // once a process each
    EXPECT_EQ(said.find("sqrt: domain error"), said.rfind("sqrt: domain error")) << said;
}

// A variable redefined after use: later evaluations (and constants folded later) see the new
// value, not one remembered from an earlier evaluation.
TEST(Calcomp, RedefinitionIsSeenByLaterEvaluations) {
    Context cx;
    cx.Load("a = 3; f(x) : x + a; y = f(1);", FileLoc{"t.cal", 1});
    cx.Load("a = 4; z = f(1); k : a;", FileLoc{"t.cal", 2});  // folded right after y's folding
    EXPECT_EQ(Eval(cx, "z"), 5);
    EXPECT_EQ(Eval(cx, "k"), 4);
    EXPECT_EQ(Eval(cx, "y"), 4);  // f is constant (':'), so f(1) was folded when y was defined
}

TEST(Calcomp, ErrorsNameFileLineAndProblem) {
    Context cx;
    EXPECT_EQ(ErrorOf([&] {
                  cx.Load("a = 1;\nb = (2;\n", FileLoc{"t.cal", 1});
              }),
              "t.cal:2: ')' expected at ';'");
    EXPECT_EQ(ErrorOf([&] {
                  cx.Load("a = 1\nb = 2;", FileLoc{"t.cal", 1});
              }),
              "t.cal:2: ';' expected at 'b = 2;'");
    EXPECT_EQ(ErrorOf([&] {
                  cx.Load("3a = 1;", FileLoc{"t.cal", 1});
              }),
              "t.cal:1: illegal variable name at '3a = 1;'");
    EXPECT_EQ(ErrorOf([&] {
                  cx.Load("c = 1 {", FileLoc{"t.cal", 1});
              }),
              "t.cal:1: '}' expected at 'end of input'");
    cx.Load("u = v + 1;\nloop(n) = loop(n) + 1;", FileLoc{"u.cal", 1});
    EXPECT_EQ(ErrorOf([&] { Eval(cx, "u"); }), "u.cal:1: undefined variable 'v'");
    EXPECT_EQ(ErrorOf([&] { Eval(cx, "loop(1)"); }), "u.cal:2: recursion without end in 'loop'");
    // A variable reaching itself through arg() (found by a 30-minute fuzz run, whose sanitizer
    // build ran out of stack before kMaxDepth calls; the evaluator now bounds its stack too:
    // fuzz/corpus/calcomp/self_through_arg.cal replays the finding).
    cx.Load("self = arg(self) + 1;", FileLoc{"s.cal", 1});
    // A constant (':') that reads the ray is evaluated for each ray, as the specialised
    // evaluation does (found by the same fuzz run: the interpreter kept the first ray's value,
    // as RADIANCE does, and answered with it where there was no ray).
    cx.Load("twice : 2 * $1;", FileLoc{"c.cal", 1});
    ChannelArray one({1}), three({3});
    EXPECT_EQ(Eval(cx, "twice", &one), 2);
    EXPECT_EQ(Eval(cx, "twice", &three), 6);
    EXPECT_NE(ErrorOf([&] { Eval(cx, "twice"); }).find("used where there is no ray"),
              std::string::npos);
    ChannelArray object({0, 0, 1});
    object.SetObjectArguments({2, .5, -1});
    EXPECT_NE(
        ErrorOf([&] { Eval(cx, "self", &object); }).find("recursion without end evaluating 'self'"),
        std::string::npos);
    EXPECT_EQ(ErrorOf([&] { Eval(cx, "sqrt"); }),
              "expr:1: 'sqrt' is a function, used as a variable");
    EXPECT_EQ(ErrorOf([&] { Eval(cx, "Dx"); }), "expr:1: undefined variable 'Dx'");
}

// Input that would overflow the stack (the parser's, or later the evaluator's and the tree's
// destructor's) is refused with its place; depths a real file uses still read.
TEST(Calcomp, DeepExpressionsAreRefusedNotCrashed) {
    const auto repeat = [](const std::string &s, int n) {
        std::string out;
        for (int i = 0; i < n; ++i) out += s;
        return out;
    };
    const std::string too_deep = "expression nested deeper than 1000 levels";
    Context cx;
    for (const std::string &e :
         {"w=" + repeat("(", 10000) + "1" + repeat(")", 10000), "x=" + repeat("2^", 20000) + "1;",
          "y=" + repeat("-(", 5000) + "1" + repeat(")", 5000) + ";",
          "z=a" + repeat("+a", 3000) + ";",
          "f=" + repeat("sin(", 3000) + "a" + repeat(")", 3000)}) {
        const std::string error = ErrorOf([&] { cx.Load(e, FileLoc{"deep.cal", 7}); });
        EXPECT_EQ(error.rfind("deep.cal:7: " + too_deep, 0), 0u) << error.substr(0, 100);
    }
    cx.Load("a = 1;\nok = " + repeat("(", 300) + "a" + repeat("+a)", 300) + ";\n",
            FileLoc{"ok.cal", 1});
    EXPECT_EQ(Eval(cx, "ok"), 301);
    // Indices that are not numbers or beyond int are errors, not undefined casts, interpreted
    // and specialised alike.
    cx.Load("big = 1e300; nan = big * big - big * big;", FileLoc{"i.cal", 1});
    for (const char *e : {"select(big, 1, 2)", "select(nan, 1, 2)", "select(-1e300, 1, 2)"}) {
        for (const bool specialised : {false, true}) {
            const std::string error = ErrorOf([&] {
                const Expression x = specialised ? cx.Compile(e, FileLoc{"expr", 1})
                                                 : cx.CompileInterpreted(e, FileLoc{"expr", 1});
                x.Evaluate(cx);
            });
            EXPECT_NE(error.find("select: index"), std::string::npos) << e << ": " << error;
        }
    }
    EXPECT_EQ(ErrorOf([&] { Eval(cx, "$99999999999 + 1"); }),
              "expr:1: channel number beyond $100000 at '99999 + 1'");
}

}  // namespace
}  // namespace dayflux::cal
