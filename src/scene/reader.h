// Reading RADIANCE scene descriptions (.rad): primitives with their arguments checked against
// their type, "#" comments, and "!command" lines whose output is read as scene text, as oconv
// does. "!xform" with the usual options (-t -rx -ry -rz -s -mx -my -mz -m -n) is done here without
// a shell, so scenes work where RADIANCE is not installed; other commands go to /bin/sh.
#pragma once

#include <string>
#include <string_view>
#include <unordered_map>

#include "scene/primitives.h"
#include "util/files.h"

namespace dayflux {

// An "!xform ..." line done without a shell: its transform, -m, -n and files ("-" if none).
struct XformCommand {
    Transform xf;
    std::string modifier;     // -m: every object's modifier
    std::string name_prefix;  // -n: "name." before every object's name
    std::vector<std::string> files;
};
// False where the command needs the real xform: not xform, shell syntax, arrays (-a), -i.
bool ParseXformCommand(const std::string &command, const FileLoc &loc, XformCommand *out);

class SceneReader {
  public:
    explicit SceneReader(Scene *scene) : scene_(scene) {}
    // The modifiers already in the scene (an octree added to, oconv -i) become ones the new
    // text may use.
    void KnowExistingModifiers();
    // Accept modifiers that are never defined (as xform does when it only rewrites text).
    void AllowUndefinedModifiers(bool allow) { allow_undefined_ = allow; }
    // path "-" reads stdin.
    void ReadFile(const std::string &path);
    void ReadText(std::string_view text, const std::string &name);
    void Read(InputSource &in);

  private:
    struct Context {
        Transform xf;
        std::string modifier_override;                         // xform -m
        std::string name_prefix;                               // xform -n
        std::shared_ptr<const std::vector<Transform>> xforms;  // the "!xform"s, innermost first
        std::string dir;  // the folder "!xform" works in (its file's), "" for the working one
        int depth = 0;
    };
    void Read(InputSource &in, const Context &cx);
    void ReadPrimitive(InputSource &in, const Context &cx);
    void RunCommand(const std::string &command, const FileLoc &loc, const Context &cx);
    void Xform(const XformCommand &xform, const Context &cx);

    Scene *scene_;
    std::unordered_map<std::string, int> modifiers_;  // latest modifier definition of each name
    bool allow_undefined_ = false;
};

// The argument counts p's type requires; an error naming p's file and line if they are wrong.
// Scene files and frozen octrees are both checked, so later stages can index arguments freely.
void CheckArguments(const Primitive &p);

// Reads several scene files (as oconv takes them) into one scene.
Scene ReadScene(const std::vector<std::string> &paths);
// As programs take their scene: octrees (oconv output) and .rad files alike, in order.
Scene LoadScene(const std::vector<std::string> &inputs);

}  // namespace dayflux
