// RADIANCE's calcomp expression language: definitions ("x = e;", "x : e;", "f(a,b) = e;"),
// + - * / ^, unary minus, calls with lazily evaluated arguments, recursion, the library functions
// (if, select, min, max, trig, ...), {comments}, $N channels for ray variables.
// Expressions are parsed once into trees whose names are resolved to symbol numbers, so evaluation
// does no string lookups.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "util/errors.h"

namespace dayflux::cal {

struct Node;
using NodePtr = std::unique_ptr<Node>;

struct Node {
    enum Kind { kNum, kVar, kArg, kChan, kCall, kAdd, kSub, kMul, kDiv, kPow, kNeg };
    Kind kind = kNum;
    double num = 0;
    int index = 0;  // symbol (kVar, and kCall's callee when it names a symbol), argument, channel
    std::vector<NodePtr> kids;  // operands; for kCall, kids[0] is the callee (kVar or kArg)
    int height = 1;             // levels of nodes from this one down to its deepest leaf
};

// Values of $1, $2, ... (the ray variables: Dx Dy Dz = $1 $2 $3, see lib/rayinit.cal).
class Channels {
  public:
    virtual ~Channels() = default;
    virtual double Value(int n) const = 0;
    // The real arguments of the object being evaluated (a pattern's A1, A2, ...), for arg(n);
    // nullptr where there is no object.
    virtual const std::vector<double> *ObjectArguments() const { return nullptr; }
    // How many columns there are, for rcalc's in(0) (0 where they are not counted).
    virtual int Count() const { return 0; }
};

class ChannelArray : public Channels {
  public:
    explicit ChannelArray(std::vector<double> v) : v_(std::move(v)) {}
    double Value(int n) const override {
        return n >= 1 && n <= static_cast<int>(v_.size()) ? v_[n - 1] : 0.0;
    }
    const std::vector<double> *ObjectArguments() const override {
        return has_args_ ? &args_ : nullptr;
    }
    std::vector<double> &values() { return v_; }
    void SetObjectArguments(std::vector<double> a) {
        args_ = std::move(a);
        has_args_ = true;
    }

  private:
    std::vector<double> v_, args_;
    bool has_args_ = false;
};

// Channels over values the caller keeps (no copies: for evaluation once per ray).
class ChannelView : public Channels {
  public:
    explicit ChannelView(std::span<const double> v, const std::vector<double> *args = nullptr)
        : v_(v), args_(args) {}
    double Value(int n) const override {
        return n >= 1 && n <= static_cast<int>(v_.size()) ? v_[n - 1] : 0.0;
    }
    const std::vector<double> *ObjectArguments() const override { return args_; }

  private:
    std::span<const double> v_;
    const std::vector<double> *args_;
};

class Context;
class SpecialisedExpression;
class DirectBins;

// A compiled expression, evaluated against a context (which holds the definitions it uses).
class Expression {
  public:
    Expression() = default;
    double Evaluate(const Context &cx, const Channels *channels = nullptr) const;
    const Node *Root() const { return root_.get(); }
    // Whether it runs specialised (specialise.h) rather than interpreted, while its context
    // keeps the definitions it was compiled with (CompileInterpreted() keeps the interpreter).
    bool Specialised() const { return fast_ != nullptr; }
    // Whether it is one of lib/'s bin functions computed directly (direct_bins.h).
    bool Direct() const { return direct_ != nullptr; }
    const std::string &Text() const { return text_; }

  private:
    friend class Context;
    NodePtr root_;
    std::string text_;
    FileLoc loc_;
    // The same, specialised to the context as it was when compiled (specialise.h); used while
    // the context's definitions stay as they were.
    std::shared_ptr<const SpecialisedExpression> fast_;
    std::shared_ptr<const DirectBins> direct_;  // kbin, rbin, ... computed directly (direct_bins.h)
    const void *fast_context_ = nullptr;
    uint64_t fast_generation_ = 0;
};

class Context {
  public:
    Context();
    ~Context();
    Context(const Context &) = delete;
    Context &operator=(const Context &) = delete;

    // Parses and adds the definitions in text; loc names where it came from for messages.
    void Load(std::string_view text, const FileLoc &loc);
    // Reads a .cal file (the caller has found it on RAYPATH).
    void LoadFile(const std::string &path);
    // Defines the ray variables (Dx = $1 ... Lv = $27) that RADIANCE's ray tracers build in, so
    // that any rayinit.cal (ours or RADIANCE's) can be loaded after them.
    void DefineRayVariables();
    // What a ray tracer's context starts with: the ray variables, dayflux's own rayinit.cal (our
    // lib/*.cal files use its helpers), then the rayinit.cal RAYPATH finds if that is another
    // one (a RADIANCE installation's, say), whose definitions win.
    void LoadRayInit();
    // rcalc's output channels: "$N = e;" definitions allowed in what is loaded after this, and
    // those defined, by N ascending, each as an expression evaluating its definition.
    void AllowOutputChannels(bool allow);
    // rcalc's in(n) (RADIANCE's l_in()): $n for n != 0, and for 0 the channels' Count(); a
    // definition of in() in what is loaded still takes its place.
    void AllowInFunction();
    std::vector<std::pair<int, Expression>> OutputChannels() const;
    // Sets or replaces a variable (as "name = value;" or with constant, "name : value;").
    void Set(const std::string &name, double value, bool constant = false);
    // Parses an expression (for example a -b bin expression).
    Expression Compile(std::string_view text, const FileLoc &loc) const;
    // The same, always interpreted: the parse tree alone (what the GPU's shader maker turns
    // into GLSL, and what the tests compare the specialised evaluation with).
    Expression CompileInterpreted(std::string_view text, const FileLoc &loc) const;

    // The names e uses, directly or through the definitions it reaches, that are neither
    // defined nor library functions: what would fail when evaluated (at the latest where a
    // branch taking them is first met), found before any evaluation.
    std::vector<std::string> UndefinedNames(const Expression &e) const;

    // Value of a variable (no arguments).
    double Value(const std::string &name, const Channels *channels = nullptr) const;

    // For code generators: the definition of a symbol.
    struct Definition {
        std::string name;
        std::vector<std::string> params;
        NodePtr body;
        bool constant = false;
        FileLoc loc;
    };
    int SymbolIndex(const std::string &name) const;  // -1 if unknown
    const std::string &SymbolName(int index) const;
    const Definition *Find(int symbol) const;

    struct Impl;  // opaque: symbols, definitions, caches

  private:
    friend class Expression;
    std::unique_ptr<Impl> impl_;
};

}  // namespace dayflux::cal
