// Running a third-party parser in a child process.
//
// Assimp 5.2 crashes or runs for minutes on some malformed files (the fuzzer
// in tools/fuzz finds such OBJ inputs in seconds). skybake promises one line
// and a non-zero exit for bad input, never a crash or a hang, so the parse
// runs in a forked child with a time limit and an address-space limit. The
// child flattens the scene itself and sends the triangles back over a pipe;
// a signal, a timeout or an allocation failure in the child becomes a
// skybake::Error in the parent.
#include <cerrno>
#include <csignal>
#include <cstring>
#include <sys/resource.h>
#include <sys/wait.h>
#include <sys/prctl.h>
#include <unistd.h>

#include <fmt/format.h>

#include "io/mesh_internal.h"
#include "skybake/error.h"
#include "skybake/interrupt.h"

#if defined(__SANITIZE_ADDRESS__)
#define SKYBAKE_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define SKYBAKE_ASAN 1
#endif
#endif

#if defined(SKYBAKE_ASAN) || defined(__SANITIZE_UNDEFINED__)
#include <sanitizer/common_interface_defs.h>
#define SKYBAKE_SANITIZER_DEATH_CALLBACK 1
#elif defined(__has_feature)
#if __has_feature(undefined_behavior_sanitizer)
#include <sanitizer/common_interface_defs.h>
#define SKYBAKE_SANITIZER_DEATH_CALLBACK 1
#endif
#endif

namespace skybake::io {

namespace {

// --- a tiny serialiser ---------------------------------------------------------------------

struct Writer {
    std::string buf;
    template <class T>
    void pod(const T& v) {
        buf.append(reinterpret_cast<const char*>(&v), sizeof(T));
    }
    void str(const std::string& s) {
        pod(std::uint64_t(s.size()));
        buf.append(s);
    }
    template <class T>
    void vec(const std::vector<T>& v) {
        pod(std::uint64_t(v.size()));
        if (!v.empty())
            buf.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
    }
};

struct Reader {
    const std::string& buf;
    std::size_t pos = 0;
    const std::string& where;
    void need(std::size_t n) {
        if (buf.size() - pos < n)
            throw Error("the isolated importer sent a truncated result", where);
    }
    template <class T>
    T pod() {
        need(sizeof(T));
        T v;
        std::memcpy(&v, buf.data() + pos, sizeof(T));
        pos += sizeof(T);
        return v;
    }
    std::string str() {
        const auto n = pod<std::uint64_t>();
        need(n);
        std::string s = buf.substr(pos, n);
        pos += n;
        return s;
    }
    template <class T>
    std::vector<T> vec() {
        const auto n = pod<std::uint64_t>();
        if (n > (buf.size() - pos) / sizeof(T))
            throw Error("the isolated importer sent a truncated result", where);
        std::vector<T> v(n);
        if (n > 0) // memcpy to an empty vector's null data() is undefined
            std::memcpy(v.data(), buf.data() + pos, n * sizeof(T));
        pos += n * sizeof(T);
        return v;
    }
};

std::string serialise(const RawImport& r) {
    Writer w;
    w.pod('M');
    w.vec(r.mesh.positions);
    w.vec(r.mesh.normals);
    w.vec(r.mesh.colors);
    w.vec(r.mesh.indices);
    w.pod(std::uint64_t(r.mesh.attributes.size()));
    for (const auto& a : r.mesh.attributes) {
        w.str(a.name);
        w.pod(std::int32_t(a.components));
        w.vec(a.values);
    }
    w.pod(std::uint64_t(r.mesh.texcoords.size()));
    for (const auto& uv : r.mesh.texcoords)
        w.vec(uv);
    w.pod(std::uint64_t(r.mesh.materials.size()));
    for (const auto& m : r.mesh.materials) {
        w.str(m.name);
        w.pod(m.base_color);
        w.str(m.base_color_texture);
        w.pod(std::int32_t(m.base_color_texcoord));
    }
    w.pod(std::uint64_t(r.mesh.parts.size()));
    for (const auto& p : r.mesh.parts) {
        w.str(p.name);
        w.pod(std::int32_t(p.material));
    }
    w.vec(r.mesh.triangle_parts);
    w.str(r.report.format);
    w.pod(std::uint64_t(r.report.source_meshes));
    w.pod(std::uint64_t(r.report.degenerate_triangles));
    w.pod(std::uint64_t(r.report.non_triangles));
    w.pod(std::uint64_t(r.report.missing_textures.size()));
    for (const std::string& t : r.report.missing_textures)
        w.str(t);
    return std::move(w.buf);
}

RawImport deserialise(const std::string& buf, const std::string& where) {
    Reader rd{buf, 0, where};
    const char tag = rd.pod<char>();
    if (tag == 'E')
        throw Error(rd.str(), where);
    if (tag != 'M')
        throw Error("the isolated importer sent an unreadable result", where);
    RawImport r;
    r.mesh.positions = rd.vec<glm::vec3>();
    r.mesh.normals = rd.vec<glm::vec3>();
    r.mesh.colors = rd.vec<glm::vec4>();
    r.mesh.indices = rd.vec<std::uint32_t>();
    const auto attrs = rd.pod<std::uint64_t>();
    if (attrs > 1024)
        throw Error("the isolated importer sent an unreadable result", where);
    for (std::uint64_t i = 0; i < attrs; ++i) {
        VertexAttribute a;
        a.name = rd.str();
        a.components = rd.pod<std::int32_t>();
        a.values = rd.vec<float>();
        r.mesh.attributes.push_back(std::move(a));
    }
    const auto uv_sets = rd.pod<std::uint64_t>();
    if (uv_sets > 64)
        throw Error("the isolated importer sent an unreadable result", where);
    for (std::uint64_t i = 0; i < uv_sets; ++i)
        r.mesh.texcoords.push_back(rd.vec<glm::vec2>());
    const auto materials = rd.pod<std::uint64_t>();
    if (materials > (std::uint64_t(1) << 20))
        throw Error("the isolated importer sent an unreadable result", where);
    for (std::uint64_t i = 0; i < materials; ++i) {
        MeshMaterial m;
        m.name = rd.str();
        m.base_color = rd.pod<glm::vec4>();
        m.base_color_texture = rd.str();
        m.base_color_texcoord = rd.pod<std::int32_t>();
        r.mesh.materials.push_back(std::move(m));
    }
    const auto parts = rd.pod<std::uint64_t>();
    if (parts > (std::uint64_t(1) << 24))
        throw Error("the isolated importer sent an unreadable result", where);
    for (std::uint64_t i = 0; i < parts; ++i) {
        MeshPart p;
        p.name = rd.str();
        p.material = rd.pod<std::int32_t>();
        r.mesh.parts.push_back(std::move(p));
    }
    r.mesh.triangle_parts = rd.vec<std::uint32_t>();
    r.report.format = rd.str();
    r.report.source_meshes = rd.pod<std::uint64_t>();
    r.report.degenerate_triangles = rd.pod<std::uint64_t>();
    r.report.non_triangles = rd.pod<std::uint64_t>();
    const auto missing = rd.pod<std::uint64_t>();
    if (missing > materials)
        throw Error("the isolated importer sent an unreadable result", where);
    for (std::uint64_t i = 0; i < missing; ++i)
        r.report.missing_textures.push_back(rd.str());
    return r;
}

bool write_all(int fd, const std::string& s) {
    std::size_t off = 0;
    while (off < s.size()) {
        const ssize_t n = ::write(fd, s.data() + off, s.size() - off);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0)
            return false;
        off += std::size_t(n);
    }
    return true;
}

[[noreturn]] void child_main(int fd, const std::function<RawImport()>& parse, const ImportLimits& limits,
                             pid_t parent) {
    // Die plainly on a fault: handlers inherited from the parent (a crash
    // reporter, a sanitizer, a fuzzer) must not run in the child; the parent
    // reports the signal as one error line.
    for (int sig : {SIGALRM, SIGSEGV, SIGBUS, SIGILL, SIGFPE, SIGABRT, SIGINT, SIGTERM})
        ::signal(sig, SIG_DFL);
#if defined(SKYBAKE_SANITIZER_DEATH_CALLBACK)
    // The same for a sanitizer's report in the child (an allocation ASan
    // cannot make, as there is no address-space limit under ASan): a fuzzer's
    // death callback would record the child's end as the fuzzer's crash.
    __sanitizer_set_death_callback(nullptr);
#endif
    // Die with the parent: a killed CLI must not leave a parser running.
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent)
        _exit(4); // the parent died before prctl took effect
    ::alarm(limits.parser_timeout_s > 0 ? limits.parser_timeout_s : 0);
#if !defined(SKYBAKE_ASAN) // ASan reserves terabytes of address space for its shadow
    if (limits.parser_memory_bytes > 0) {
        rlimit rl{rlim_t(limits.parser_memory_bytes), rlim_t(limits.parser_memory_bytes)};
        ::setrlimit(RLIMIT_AS, &rl);
    }
#endif
    std::string out;
    try {
        out = serialise(parse());
    } catch (const Error& e) {
        Writer w;
        w.pod('E');
        w.str(e.message());
        out = std::move(w.buf);
    } catch (const std::bad_alloc&) {
        Writer w;
        w.pod('E');
        w.str(fmt::format("the importer ran out of memory (limit {} MiB); the file is too large or malformed",
                          limits.parser_memory_bytes >> 20));
        out = std::move(w.buf);
    } catch (const std::exception& e) {
        Writer w;
        w.pod('E');
        w.str(fmt::format("the importer failed: {}", e.what()));
        out = std::move(w.buf);
    }
    _exit(write_all(fd, out) ? 0 : 3);
}

} // namespace

RawImport run_isolated(const std::function<RawImport()>& parse, const std::string& where,
                       const ImportLimits& limits) {
    if (!limits.isolate_parsers)
        return parse();
    int fds[2];
    if (::pipe(fds) != 0)
        throw Error(fmt::format("cannot create a pipe: {}", std::strerror(errno)), where);
    const pid_t parent = ::getpid();
    const pid_t pid = ::fork();
    if (pid < 0) {
        ::close(fds[0]);
        ::close(fds[1]);
        throw Error(fmt::format("cannot start the importer process: {}", std::strerror(errno)), where);
    }
    if (pid == 0) {
        ::close(fds[0]);
        child_main(fds[1], parse, limits, parent);
    }
    ::close(fds[1]);
    std::string buf;
    char chunk[1 << 16];
    for (;;) {
        const ssize_t n = ::read(fds[0], chunk, sizeof(chunk));
        if (n < 0 && errno == EINTR) {
            if (interrupt_signal() != 0) { // SIGINT/SIGTERM: stop the parser, then report
                ::kill(pid, SIGKILL);
                ::close(fds[0]);
                int status = 0;
                while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
                }
                check_interrupted();
            }
            continue;
        }
        if (n <= 0)
            break;
        buf.append(chunk, std::size_t(n));
    }
    ::close(fds[0]);
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    check_interrupted(); // a signal that came before the read blocked
    if (WIFSIGNALED(status)) {
        const int sig = WTERMSIG(status);
        if (sig == SIGALRM)
            throw Error(fmt::format("the importer took longer than {} s; the file is probably malformed",
                                    limits.parser_timeout_s),
                        where);
        throw Error(fmt::format("the importer crashed on this file ({}); the file is malformed",
                                sig == SIGSEGV ? "segmentation fault" : sig == SIGABRT ? "abort" : strsignal(sig)),
                    where);
    }
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || buf.empty())
        throw Error("the importer stopped without a result; the file is probably malformed", where);
    return deserialise(buf, where);
}

} // namespace skybake::io
