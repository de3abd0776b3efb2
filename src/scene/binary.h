// RADIANCE's portable binary encoding, shared by octrees (.oct) and meshes (.rtm): big-endian
// sign-extended integers, null-terminated strings, reals with a 31-bit mantissa, pre-order trees,
// and objects stored after a table of type names.
#pragma once

#include <functional>
#include <string>
#include <string_view>

#include "scene/primitives.h"
#include "util/files.h"

namespace dayflux {

class RadianceBinaryInput {
  public:
    // what names the data in messages ("octree", "mesh file").
    RadianceBinaryInput(InputSource &in, std::string what) : in_(in), what_(std::move(what)) {}
    [[noreturn]] void Fail(const std::string &msg) const;
    // Reads the text header and checks its FORMAT= line; returns the other header lines.
    std::string Header(const std::string &format);
    int Byte();
    long Int(int nbytes);
    std::string String();
    double Real();
    // Skips a pre-order octree whose leaves hold sets of objsize-byte numbers.
    void SkipTree(int objsize, int depth = 0);
    // Reads the type table and the objects that follow it into scene (modifiers relative to the
    // first object read); returns the number read.
    long Objects(int objsize, Scene *scene);

  private:
    InputSource &in_;
    std::string what_;
};

// The writing side (common/portio.c): bytes handed to sink a megabyte at a time (and the rest
// by Flush()), or, without a sink, kept for Bytes().
class RadianceBinaryOutput {
  public:
    using Sink = std::function<void(std::string_view)>;
    explicit RadianceBinaryOutput(Sink sink = nullptr) : sink_(std::move(sink)) {}
    void Byte(int c) {
        bytes_.push_back(static_cast<char>(c));
        if (sink_ && bytes_.size() >= kChunk) Flush();
    }
    void Int(long value, int nbytes);
    void String(const std::string &s);
    // frexp's mantissa in 31 bits and its exponent in one byte (putflt()).
    void Real(double value);
    const std::string &Bytes() const { return bytes_; }
    void Flush() {
        if (sink_ && !bytes_.empty()) sink_(bytes_);
        bytes_.clear();
    }

  private:
    static constexpr size_t kChunk = 1 << 20;
    Sink sink_;
    std::string bytes_;
};

}  // namespace dayflux
