#include "util/files.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstring>

#include "util/signals.h"

namespace dayflux {

namespace {
constexpr size_t kBufferSize = 1 << 20, kPipeBufferSize = 1 << 16;

// The standard input's and output's pipes, widened from Linux's 64 KiB to 1 MiB (the most an
// unprivileged process may ask for by default), and what we read from one at a time: a year of
// products (150 MB) through `dctimestep | rmtxop` took 2,300 turns between the programs. Best
// effort: where the system refuses, the pipe stays as it was.
constexpr int kPipeCapacity = 1 << 20;
void WidenPipe(int fd) {
    struct stat st;
    if (fstat(fd, &st) == 0 && S_ISFIFO(st.st_mode) && fcntl(fd, F_GETPIPE_SZ) < kPipeCapacity)
        fcntl(fd, F_SETPIPE_SZ, kPipeCapacity);
}

bool IsSpace(int c) {
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v';
}
}  // namespace

namespace {
bool commands_in_data_files = true;
}  // namespace

void AllowCommandsInDataFiles(bool allow) { commands_in_data_files = allow; }

bool CopyStream(std::FILE *in, std::FILE *out) {
    std::fflush(out);
    char buf[1 << 16];
    for (size_t n; (n = std::fread(buf, 1, sizeof buf, in)) > 0;)
        if (std::fwrite(buf, 1, n, out) != n) return false;
    return std::fflush(out) == 0 && !std::ferror(in);
}
bool CommandsInDataFilesAllowed() { return commands_in_data_files; }

std::unique_ptr<InputSource> InputSource::OpenNamedIn(const std::string &spec, const FileLoc &loc) {
    if (!spec.empty() && spec[0] == '!' && !commands_in_data_files)
        ErrorExit(&loc, "'" + spec.substr(0, 60) +
                            "': commands in data files are refused (-no_commands)");
    return Open(spec);
}

std::unique_ptr<InputSource> InputSource::Open(const std::string &spec) {
    std::unique_ptr<InputSource> in(new InputSource());
    if (spec.empty() || spec == "-") {
        in->name_ = kStdinName;
        in->fp_ = stdin;
        in->is_stdin_ = true;
    } else if (spec[0] == '!') {
        in->name_ = spec;
        std::fflush(nullptr);
        in->fp_ = popen(spec.c_str() + 1, "r");
        if (!in->fp_) ErrorExit("cannot start command '" + spec + "'");
        in->is_pipe_ = true;
    } else {
        in->name_ = spec;
        struct stat st;
        if (stat(spec.c_str(), &st) == 0 && S_ISDIR(st.st_mode))
            ErrorExit("cannot open file '" + spec + "': is a directory");
        in->fp_ = std::fopen(spec.c_str(), "rb");
        if (!in->fp_) ErrorExit("cannot open file '" + spec + "': " + std::strerror(errno));
    }
    // A small file gets a small buffer (scenes open many), a pipe what it can hold at once: the
    // standard input's widened (matrices come that way), a command's left as it is (scenes'
    // !xform, many at once: each widened pipe counts against the user's pipe pages).
    if (in->is_stdin_) WidenPipe(fileno(in->fp_));
    struct stat st;
    size_t size = in->is_stdin_ ? kPipeCapacity : kPipeBufferSize;
    if (fstat(fileno(in->fp_), &st) == 0 && S_ISREG(st.st_mode)) {
        size = std::clamp<size_t>(static_cast<size_t>(st.st_size) + 1, 4096, kBufferSize);
        in->regular_ = true;
    }
    in->buf_.resize(size);
    return in;
}

std::unique_ptr<InputSource> InputSource::FromString(std::string data, std::string name) {
    std::unique_ptr<InputSource> in(new InputSource());
    in->name_ = std::move(name);
    in->buf_.assign(data.begin(), data.end());
    in->end_ = in->buf_.size();
    in->eof_ = true;
    return in;
}

InputSource::~InputSource() {
    if (fp_ && !is_stdin_) {
        if (is_pipe_)
            pclose(fp_);
        else
            std::fclose(fp_);
    }
}

bool InputSource::Close() {
    if (!fp_ || is_stdin_) return true;
    if (is_pipe_) {
        int status = pclose(fp_);
        fp_ = nullptr;
        if (status != 0) {
            Warning("error running command '" + name_ + "'");
            return false;
        }
    } else {
        std::fclose(fp_);
        fp_ = nullptr;
    }
    return true;
}

std::optional<uint64_t> InputSource::BytesLeft() const {
    const uint64_t buffered = end_ - pos_;
    if (!fp_) return buffered;
    if (is_pipe_) return std::nullopt;
    struct stat st;
    if (fstat(fileno(fp_), &st) != 0 || !S_ISREG(st.st_mode)) return std::nullopt;
    const off_t at = lseek(fileno(fp_), 0, SEEK_CUR);
    if (at < 0 || at > st.st_size) return std::nullopt;
    return buffered + static_cast<uint64_t>(st.st_size - at);
}

bool InputSource::Fill() {
    if (eof_ || !fp_) return false;
    // Bytes not yet handed out move to the front; more are read after them.
    const size_t left = end_ - pos_;
    if (left > 0 && pos_ > 0) std::memmove(buf_.data(), buf_.data() + pos_, left);
    pos_ = 0;
    end_ = left;
    // A run asked to stop by a signal must not wait for a pipe that may never speak again.
    if (!WaitForInput()) return false;
    // read(), not fread(): it returns what a pipe holds now instead of waiting for a full
    // buffer, so a caller that feeds rays and waits for their records is answered.
    ssize_t n;
    do n = ::read(fileno(fp_), buf_.data() + left, buf_.size() - left);
    while (n < 0 && errno == EINTR);
    if (n < 0) {
        FileLoc loc = LocNoLine();
        ErrorExit(&loc, std::string("read error: ") + std::strerror(errno));
    }
    if (n == 0) {
        eof_ = true;
        return false;
    }
    end_ += static_cast<size_t>(n);
    return true;
}

bool InputSource::WaitForInput() {
    const int wake = StopOnSignals::WakeFd();
    if (wake < 0 || regular_) return true;
    struct pollfd fds[2] = {{fileno(fp_), POLLIN, 0}, {wake, POLLIN, 0}};
    for (;;) {
        if (StopOnSignals::Requested()) return false;
        if (poll(fds, 2, -1) < 0 && errno != EINTR) return true;  // read() reports the rest
        if (fds[0].revents) return true;
        if (fds[1].revents && StopOnSignals::Requested()) return false;
    }
}

std::string_view InputSource::PeekBytes(size_t n) {
    if (buf_.size() < n) buf_.resize(n);
    while (end_ - pos_ < n)
        if (!Fill()) break;
    return std::string_view(buf_.data() + pos_, std::min(n, end_ - pos_));
}

int InputSource::PeekSecond() {
    while (end_ - pos_ < 2)
        if (!Fill()) return -1;
    return static_cast<unsigned char>(buf_[pos_ + 1]);
}

size_t InputSource::Read(void *dst, size_t n) {
    char *out = static_cast<char *>(dst);
    size_t done = 0;
    while (done < n) {
        if (pos_ == end_ && !Fill()) break;
        size_t take = std::min(n - done, end_ - pos_);
        std::memcpy(out + done, buf_.data() + pos_, take);
        pos_ += take;
        done += take;
    }
    return done;
}

std::string InputSource::ReadAll() {
    std::string all;
    while (pos_ < end_ || Fill()) {
        all.append(buf_.data() + pos_, end_ - pos_);
        line_ += static_cast<int>(std::count(buf_.data() + pos_, buf_.data() + end_, '\n'));
        pos_ = end_;
    }
    return all;
}

bool InputSource::ReadLine(std::string *line) {
    line->clear();
    bool any = false;
    for (;;) {
        if (pos_ == end_ && !Fill()) return any;
        any = true;
        const char *start = buf_.data() + pos_;
        const void *nl = std::memchr(start, '\n', end_ - pos_);
        if (nl) {
            size_t len = static_cast<const char *>(nl) - start;
            line->append(start, len);
            pos_ += len + 1;
            ++line_;
            return true;
        }
        line->append(start, end_ - pos_);
        pos_ = end_;
    }
}

bool InputSource::NextWord(std::string_view *word) {
    int c;
    while ((c = Peek()) >= 0 && IsSpace(c)) Get();
    if (c < 0) return false;
    // Fast path: the word ends inside the buffer.
    size_t start = pos_;
    size_t i = pos_;
    while (i < end_ && !IsSpace(static_cast<unsigned char>(buf_[i]))) ++i;
    if (i < end_) {
        pos_ = i;
        *word = std::string_view(buf_.data() + start, i - start);
        return true;
    }
    word_.assign(buf_.data() + start, end_ - start);
    pos_ = end_;
    while ((c = Peek()) >= 0 && !IsSpace(c)) word_.push_back(static_cast<char>(Get()));
    *word = word_;
    return true;
}

bool InputSource::OnlySpaceLeft() {
    int c;
    while ((c = Peek()) >= 0) {
        if (!IsSpace(c)) return false;
        Get();
    }
    return true;
}

namespace {

// The descriptor a name of the process's own open files stands for (/dev/stdout, /dev/fd/N,
// /proc/self/fd/N), or -1.
int DescriptorNamed(const std::string &path) {
    if (path == "/dev/stdout") return 1;
    if (path == "/dev/stderr") return 2;
    const std::string own = "/proc/" + std::to_string(getpid()) + "/fd/";
    for (const std::string &prefix :
         {std::string("/dev/fd/"), std::string("/proc/self/fd/"), own}) {
        if (path.size() <= prefix.size() || path.size() > prefix.size() + 6 ||
            path.compare(0, prefix.size(), prefix) != 0)
            continue;
        const std::string digits = path.substr(prefix.size());
        if (digits.find_first_not_of("0123456789") == std::string::npos) return std::stoi(digits);
    }
    return -1;
}

}  // namespace

OutputTarget ResolveOutput(const std::string &path) {
    // Linux follows at most 40 links in a path; so do we, a link at a time, because the rename
    // must land on the final target and a dangling link's target is still to be made.
    std::string at = path;
    for (int hops = 0; hops <= 40; ++hops) {
        const int fd = DescriptorNamed(at);
        if (fd >= 0) return {at, true, fd};
        struct stat st;
        if (lstat(at.c_str(), &st) != 0) return {at, false, -1};  // made by the rename
        if (!S_ISLNK(st.st_mode)) return {at, !S_ISREG(st.st_mode), -1};
        // A link of /proc names an open file ("pipe:[123]"), not a path: opened as it is.
        if (at.rfind("/proc/", 0) == 0) return {at, true, -1};
        std::string to(PATH_MAX, '\0');
        const ssize_t n = readlink(at.c_str(), to.data(), to.size());
        if (n <= 0) return {at, true, -1};  // the open says why
        to.resize(static_cast<size_t>(n));
        const size_t slash = at.rfind('/');
        if (to[0] != '/' && slash != std::string::npos) to = at.substr(0, slash + 1) + to;
        at = to;
    }
    ErrorExit("cannot open '" + path + "' for output: too many levels of symbolic links");
}

OutputFile::OutputFile(const std::string &spec, uint64_t keep_bytes) {
    if (spec.empty() || spec == "-") {
        name_ = "<stdout>";
        fp_ = stdout;
        is_stdout_ = true;
        WidenPipe(fileno(stdout));
        return;
    }
    name_ = spec;
    if (spec[0] == '!') {
        std::fflush(nullptr);
        fp_ = popen(spec.c_str() + 1, "w");
        if (!fp_) ErrorExit("cannot start command '" + spec + "'");
        is_pipe_ = true;
        return;
    }
    const OutputTarget target = ResolveOutput(spec);
    if (target.direct && keep_bytes > 0)
        ErrorExit("cannot continue '" + spec + "': it is not a regular file");
    const int fd = target.direct ? OpenDirect(target) : OpenPartial(target.path, keep_bytes);
    fp_ = fdopen(fd, "wb");
    if (!fp_) {
        close(fd);
        ErrorExit("cannot open '" + name_ + "' for output: " + std::strerror(errno));
    }
    std::setvbuf(fp_, nullptr, _IOFBF, kBufferSize);
}

// A FIFO, a device or a descriptor: written in place as RADIANCE's fopen(name, "w") writes it.
// A descriptor is duplicated, not opened anew, so a shell's ">>" or a file shared with other
// writers keeps its offset.
int OutputFile::OpenDirect(const OutputTarget &target) {
    is_direct_ = true;
    if (target.fd >= 0) std::fflush(nullptr);
    int fd;
    do
        fd = target.fd >= 0
                 ? fcntl(target.fd, F_DUPFD_CLOEXEC, 3)
                 : open(target.path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    while (fd < 0 && errno == EINTR);  // a FIFO's open waits for its reader
    if (fd < 0) ErrorExit("cannot open '" + name_ + "' for output: " + std::strerror(errno));
    return fd;
}

// The partial file beside target, locked, holding its first keep_bytes.
int OutputFile::OpenPartial(const std::string &target, uint64_t keep_bytes) {
    target_ = target;
    temp_ = target + ".partial";
    const int fd = open(temp_.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC, 0666);
    if (fd < 0) ErrorExit("cannot open '" + name_ + "' for output: " + std::strerror(errno));
    // The lock ends with the process, so a partial file left by a killed run is free again.
    // File systems without locks (some NFS and Lustre mounts) only lose the check.
    if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
        if (errno == EWOULDBLOCK) {
            close(fd);
            ErrorExit("cannot write '" + name_ + "': another run is writing it ('" + temp_ +
                      "' is locked)");
        }
        static bool warned = false;
        if (!warned)
            Warning("'" + temp_ + "': no file locks here (" + std::strerror(errno) +
                    "): two runs writing one output would not be stopped");
        warned = true;
    }
    continues_partial_ = keep_bytes > 0;
    if (ftruncate(fd, static_cast<off_t>(keep_bytes)) != 0 ||
        lseek(fd, 0, SEEK_END) != static_cast<off_t>(keep_bytes)) {
        close(fd);
        ErrorExit("cannot write '" + temp_ + "': " + std::strerror(errno));
    }
    return fd;
}

OutputFile::~OutputFile() {
    if (finished_) return;
    if (is_pipe_) {
        if (fp_) pclose(fp_);
    } else if (!is_stdout_) {
        if (fp_) std::fclose(fp_);
        // A partial file this run continued held records before it: they stay.
        if (!continues_partial_ && !is_direct_) std::remove(temp_.c_str());
    }
}

void OutputFile::Write(const void *data, size_t n) {
    if (n && std::fwrite(data, 1, n, fp_) != n)
        ErrorExit("write error on " + name_ + ": " + std::strerror(errno));
}

void OutputFile::Commit() {
    if (finished_) return;
    if (is_stdout_) {
        finished_ = true;
        if (std::fflush(fp_) != 0)
            ErrorExit("write error on output: " + std::string(std::strerror(errno)));
        return;
    }
    if (is_pipe_) {
        finished_ = true;
        int status = pclose(fp_);
        fp_ = nullptr;
        if (status != 0) ErrorExit("error running command '" + name_ + "'");
        return;
    }
    // Renamed while the lock is held, so no other run can truncate the file in between. On a
    // write error the partial file stays for the destructor to remove or KeepPartial() to keep.
    errno = 0;
    if (std::fflush(fp_) != 0 || std::ferror(fp_))
        ErrorExit("error writing to '" + name_ + "': " + std::strerror(errno));
    if (!is_direct_ && std::rename(temp_.c_str(), target_.c_str()) != 0)
        ErrorExit("cannot rename '" + temp_ + "' to '" + target_ + "': " + std::strerror(errno));
    finished_ = true;
    const bool closed = std::fclose(fp_) == 0;
    fp_ = nullptr;
    if (!closed) {
        const std::string why = std::strerror(errno);
        if (!is_direct_) std::remove(target_.c_str());
        ErrorExit("error writing to '" + name_ + "': " + why);
    }
}

bool OutputFile::KeepPartial() {
    if (finished_) return true;
    finished_ = true;
    if (!fp_) return false;  // a Commit() that failed
    bool ok = std::fflush(fp_) == 0 && !std::ferror(fp_);
    if (is_pipe_)
        pclose(fp_);
    else if (!is_stdout_)
        ok = std::fclose(fp_) == 0 && ok;
    fp_ = nullptr;
    return ok;
}

}  // namespace dayflux
