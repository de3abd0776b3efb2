// Inputs and outputs as RADIANCE programs name them: a file, "-" for the standard streams, or
// "!command" for a shell pipe. Outputs to regular files are written to a temporary beside the
// target and renamed on success, so a failed run never leaves a complete-looking file behind;
// FIFOs, devices and the standard streams' names are written directly, since a rename would
// replace the node.
#pragma once

#include <cstdint>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "util/errors.h"

namespace dayflux {

// The name RADIANCE uses for the standard input in messages.
inline constexpr const char *kStdinName = "<stdin>";

// What is left of in, copied to out as it is (out flushed before and after, so that it follows
// what was written to it through stdio); false where either fails.
bool CopyStream(std::FILE *in, std::FILE *out);

// A buffered byte source with line counting for text and raw reads for binary data.
// Whether "!command" inputs named inside data files (scene lines, octrees' file lists, rfluxmtx's
// sender and receiver files) run, as in RADIANCE: yes unless a program's -no_commands turned it
// off, for services that open files they did not write. "!xform" with the options the readers
// do in-process is not a command and stays allowed.
void AllowCommandsInDataFiles(bool allow);
bool CommandsInDataFilesAllowed();

class InputSource {
  public:
    // spec: a path, "-" or "" for stdin, or "!command" (run with /bin/sh, its stdout read).
    static std::unique_ptr<InputSource> Open(const std::string &spec);
    // The same for a spec named inside a data file at loc: a "!command" is an error there when
    // commands in data files are not allowed.
    static std::unique_ptr<InputSource> OpenNamedIn(const std::string &spec, const FileLoc &loc);
    // For tests and in-memory data.
    static std::unique_ptr<InputSource> FromString(std::string data, std::string name);
    ~InputSource();
    InputSource(const InputSource &) = delete;
    InputSource &operator=(const InputSource &) = delete;

    const std::string &Name() const { return name_; }
    // Line number of the next unread byte, counting from 1.
    int Line() const { return line_; }
    FileLoc Loc() const { return FileLoc{name_, line_}; }
    FileLoc LocNoLine() const { return FileLoc{name_, 0}; }

    int Get() {
        if (pos_ == end_ && !Fill()) return -1;
        char c = buf_[pos_++];
        if (c == '\n') ++line_;
        return static_cast<unsigned char>(c);
    }
    int Peek() {
        if (pos_ == end_ && !Fill()) return -1;
        return static_cast<unsigned char>(buf_[pos_]);
    }
    // The byte after the next one, or -1 (for telling "-Y 3 +X 4" from "-3 ...").
    int PeekSecond();
    // Up to n of the next bytes, without reading them (fewer only at the end of input); valid
    // until the next call on this source.
    std::string_view PeekBytes(size_t n);
    // Reads up to n bytes of binary data; returns the count read (less only at end of input).
    size_t Read(void *dst, size_t n);
    // Reads one line without its '\n'; false at end of input with nothing read.
    bool ReadLine(std::string *line);
    // Skips white space and returns the next white-space separated word, or false at the end.
    // The view stays valid until the next call on this source.
    bool NextWord(std::string_view *word);
    // The rest of the input (for small text files read whole).
    std::string ReadAll();
    // The bytes not yet read where that is known (in-memory data and regular files, standard
    // input included when it is one), for checking sizes a header claims before allocating.
    std::optional<uint64_t> BytesLeft() const;
    // True when nothing but white space is left.
    bool OnlySpaceLeft();
    bool AtEnd() { return Peek() < 0; }
    // Closes the source; a command that exited non-zero gives a warning as RADIANCE does.
    // Returns false for such a command.
    bool Close();

  private:
    InputSource() = default;
    bool Fill();
    // False when a stop was asked for (StopOnSignals) while waiting on a pipe.
    bool WaitForInput();

    std::string name_;
    FILE *fp_ = nullptr;
    bool is_pipe_ = false;
    bool is_stdin_ = false;
    bool regular_ = false;  // a regular file: never waits
    bool eof_ = false;
    std::vector<char> buf_;
    size_t pos_ = 0, end_ = 0;
    int line_ = 1;
    std::string word_;
};

// Where an output path is written. RADIANCE's fopen(name, "w") writes through symbolic links, so
// a link's final target is the file written (and renamed onto). Anything that exists and is not
// a regular file (a FIFO, a device, a socket) and the links of /proc (/dev/stdout, /dev/fd/N) are
// written directly.
struct OutputTarget {
    std::string path;     // the file to write or rename onto
    bool direct = false;  // written in place, never through a partial file
    int fd = -1;          // >= 0: the name is this process's descriptor fd (/dev/stdout)
};
OutputTarget ResolveOutput(const std::string &path);

// A destination for program output: stdout ("-" or ""), "!command", or a regular file written as
// "name.partial" beside it (beside a symbolic link's target) and renamed onto it when complete. A
// run that stops early leaves the partial file (which -r can continue) or, after an error,
// nothing; the partial file is locked while it is written, so two runs never write one output at
// once. FIFOs and devices are written directly (ResolveOutput).
class OutputFile {
  public:
    // keep_bytes > 0: continue the partial file after its first keep_bytes (which it must hold).
    explicit OutputFile(const std::string &spec, uint64_t keep_bytes = 0);
    ~OutputFile();
    OutputFile(const OutputFile &) = delete;
    OutputFile &operator=(const OutputFile &) = delete;

    // The partial file an output named spec is written to (beside a link's target).
    static std::string PartialName(const std::string &spec) {
        return ResolveOutput(spec).path + ".partial";
    }

    FILE *Stream() { return fp_; }
    const std::string &Name() const { return name_; }
    // A file written through a partial file (what -r can continue).
    bool IsFile() const { return !is_pipe_ && !is_stdout_ && !is_direct_; }
    void Write(const void *data, size_t n);
    void Write(std::string_view s) { Write(s.data(), s.size()); }
    // Flushes and, for files, renames the partial file onto the target. Throws on a write error.
    void Commit();
    // Flushes and closes, keeping a file's partial file (for -r) instead of removing it; false
    // when what was written could not all be flushed.
    bool KeepPartial();

  private:
    // The descriptor written: the node itself, or the partial file.
    int OpenDirect(const OutputTarget &target);
    int OpenPartial(const std::string &target, uint64_t keep_bytes);

    std::string name_;
    std::string temp_;    // the partial file
    std::string target_;  // what it is renamed onto: name_, or a symbolic link's target
    FILE *fp_ = nullptr;
    bool is_pipe_ = false;
    bool is_stdout_ = false;
    bool is_direct_ = false;          // a FIFO, a device or a descriptor, written in place
    bool finished_ = false;           // committed, or kept partial
    bool continues_partial_ = false;  // opened on the records of an earlier run (-r)
};

}  // namespace dayflux
