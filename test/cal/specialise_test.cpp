// Specialised expressions (src/cal/specialise.h) against the interpreter: the same numbers, bit
// for bit, for the bin functions of lib/; the interpreter for what is not specialised, and once
// the context changes.
#include "cal/specialise.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <random>

#include "cal/calcomp.h"

namespace dayflux::cal {
namespace {

std::string Lib(const char *f) { return std::string(DAYFLUX_LIB_DIR) + "/" + f; }

Expression Interpreted(const Context &cx, const std::string &text) {
    return cx.CompileInterpreted(text, FileLoc{"-b", 0});
}

// Random directions, then the axes and the diagonals of the axis planes, where zeros of either
// sign meet atan2 and the bins' boundaries.
std::vector<std::array<double, 3>> Directions() {
    std::mt19937_64 rng(7);
    std::normal_distribution<double> g;
    std::vector<std::array<double, 3>> d;
    for (int i = 0; i < 100000; ++i) {
        const double x = g(rng), y = g(rng), z = g(rng), r = std::sqrt(x * x + y * y + z * z);
        d.push_back({x / r, y / r, z / r});
    }
    const double s = std::sqrt(.5);
    for (double a : {-1., -0., 0., 1.})
        d.push_back({a, 0, 0}), d.push_back({0, a, 0}), d.push_back({0, 0, a});
    for (double a : {-s, s})
        for (double b : {-s, s}) d.push_back({a, b, 0}), d.push_back({a, 0, b});
    return d;
}

void ExpectSameAsInterpreter(Context &cx, const std::string &text) {
    const Expression fast = cx.Compile(text, FileLoc{"-b", 0});
    const Expression slow = Interpreted(cx, text);
    ASSERT_TRUE(fast.Specialised()) << text;
    ASSERT_FALSE(slow.Specialised());
    ChannelArray ray(std::vector<double>(27, 0.0));
    int differ = 0;
    for (const auto &d : Directions()) {
        std::copy(d.begin(), d.end(), ray.values().begin());
        const double a = fast.Evaluate(cx, &ray), b = slow.Evaluate(cx, &ray);
        if (std::memcmp(&a, &b, sizeof a) != 0 && ++differ < 5)
            ADD_FAILURE() << text << " at " << d[0] << " " << d[1] << " " << d[2] << ": " << a
                          << " against " << b;
    }
    EXPECT_EQ(differ, 0) << text;
}

TEST(Specialise, BinFunctionsGiveTheInterpretersNumbers) {
    Context klems;
    klems.LoadRayInit();
    klems.LoadFile(Lib("klems_full.cal"));
    for (const char *b : {"kbin(0,1,0,0,0,1)", "kbinN", "kbinE", "kbinW", "kbinD"})
        ExpectSameAsInterpreter(klems, b);
    klems.Set("RHS", -1);
    ExpectSameAsInterpreter(klems, "kbin(0,-1,0,0,0,1)");
    for (int mf : {1, 2, 6}) {
        Context reinhart;
        reinhart.LoadRayInit();
        reinhart.Set("MF", mf, true);
        reinhart.LoadFile(Lib("reinhart.cal"));
        ExpectSameAsInterpreter(reinhart, "rbin");
    }
    Context tregenza;
    tregenza.LoadRayInit();
    tregenza.LoadFile(Lib("tregenza.cal"));
    ExpectSameAsInterpreter(tregenza, "tbin");
}

// The specialised code jumps over what if(), select() and a zero divisor leave out, and computes
// a variable or an argument once, on its first use: the interpreter's numbers and its laziness
// (an out-of-range select() or a missing ray in a branch not taken is no error).
TEST(Specialise, BranchesAndSharedValuesAsTheInterpreter) {
    Context cx;
    cx.Load(
        "a = $1; b = $2; sq(x) = x * x; two(x, y) = sq(x) + sq(y) + x;"
        "pick(k) = select(k, a, b, sq(a + b), max(a, b, 1), min(b, a));"
        "guard = if(a - 5, select(b * b + 99, 1), 2) + if(b, 1 / 0, select(a * a + 99, 1) / (b - "
        "b));",
        FileLoc{"t.cal", 1});
    const char *texts[] = {"two(a + 1, b) + two(b, a)",
                           "pick(0) + pick(1) + pick(2) + pick(3)",
                           "pick(4) - pick(5)",
                           "guard",
                           "if(a, if(b, a / b, b / a), -a) ^ 2",
                           "select(if(a, 1, 2), two(a, a), sq(two(b, b)))"};
    for (const char *text : texts) {
        const Expression fast = cx.Compile(text, FileLoc{"-b", 0});
        const Expression slow = Interpreted(cx, text);
        ASSERT_TRUE(fast.Specialised()) << text;
        for (double x : {-1.5, -0.0, 0.0, 0.5, 2.0})
            for (double y : {-2.0, 0.0, 0.25, 3.0}) {
                ChannelArray ray({x, y});
                const double f = fast.Evaluate(cx, &ray), w = slow.Evaluate(cx, &ray);
                EXPECT_EQ(std::memcmp(&f, &w, sizeof f), 0)
                    << text << " at " << x << " " << y << ": " << f << " against " << w;
            }
    }
    // and what it does evaluate still fails as the interpreter does
    EXPECT_THROW(cx.Compile("select(a + 9, 1)", FileLoc{"-b", 0}).Evaluate(cx, nullptr), UserError);
}

TEST(Specialise, InlinesCallsAndFoldsWhatDoesNotDependOnTheRay) {
    Context cx;
    cx.Load("x = $1; k = 3; sq(a) = a*a; f(a, b) = if(b, sq(a) + k, select(2, 0, a));",
            FileLoc{"t.cal", 1});
    const Expression e = cx.Compile("f(x + 1, k - 1)", FileLoc{"-b", 0});
    ASSERT_TRUE(e.Specialised());
    ChannelArray ray({2.0});
    EXPECT_EQ(e.Evaluate(cx, &ray), 12);
    EXPECT_EQ(cx.Compile("f(x, 0)", FileLoc{"-b", 0}).Evaluate(cx, &ray), 2);
    // A definition changed after compiling: the interpreter answers with the new one.
    cx.Set("k", 5);
    EXPECT_EQ(e.Evaluate(cx, &ray), 14);
}

TEST(Specialise, LeavesToTheInterpreterWhatItDoesNotHandle) {
    Context cx;
    cx.Load("fact(n) = if(n - .5, n*fact(n-1), 1); g(h, x) = h(x) + 1; sq(x) = x*x;",
            FileLoc{"t.cal", 1});
    for (const char *text : {"fact(5)", "g(sq, 3)", "arg(1)", "undefined + 1", "select(4, 1, 2)"})
        EXPECT_FALSE(cx.Compile(text, FileLoc{"-b", 0}).Specialised()) << text;
    // Inlining would copy f0's body 2^20 times here.
    std::string doubling = "f0(x) = x + x;";
    for (int k = 1; k <= 20; ++k)
        doubling += " f" + std::to_string(k) + "(x) = f" + std::to_string(k - 1) + "(x) + f" +
                    std::to_string(k - 1) + "(x);";
    cx.Load(doubling, FileLoc{"d.cal", 1});
    const Expression deep = cx.Compile("f20(1)", FileLoc{"-b", 0});
    EXPECT_FALSE(deep.Specialised());
    EXPECT_EQ(deep.Evaluate(cx), 1 << 21);
    EXPECT_TRUE(cx.Compile("f10(1)", FileLoc{"-b", 0}).Specialised());
    EXPECT_EQ(cx.Compile("fact(5)", FileLoc{"-b", 0}).Evaluate(cx), 120);
    EXPECT_EQ(cx.Compile("g(sq, 3)", FileLoc{"-b", 0}).Evaluate(cx), 10);
}

TEST(Specialise, ReportsTheInterpretersErrors) {
    Context cx;
    cx.Load("x = $1;", FileLoc{"t.cal", 1});
    const Expression e = cx.Compile("select(x, 1, 2)", FileLoc{"-b", 0});
    ASSERT_TRUE(e.Specialised());
    ChannelArray ray({4.0});
    try {
        e.Evaluate(cx, &ray);
        ADD_FAILURE() << "no error";
    } catch (const UserError &err) {
        EXPECT_STREQ(err.what(), "-b: select: index 4 out of range");
    }
    try {
        e.Evaluate(cx);
        ADD_FAILURE() << "no error";
    } catch (const UserError &err) {
        EXPECT_STREQ(err.what(), "-b: ray variable $1 used where there is no ray");
    }
}

}  // namespace
}  // namespace dayflux::cal
