#pragma once
// Loading a level in a child process first. assimp reads other people's
// files, and some files crash it (a segmentation fault in an importer) or
// make it take all the memory: loaded in this process, such a file would end
// the program. The child (this program again: `sandbox __load-level`) loads
// the level, with its checks, and decodes its textures as the renderer will,
// under the level's limits on address space and CPU time ([level]
// max_import_mb, max_import_s); its crash, a limit or an error becomes a
// LevelError naming the file it was reading. On success the caller loads the
// level itself (the same input gives the same result).
//
// Threads: the calling thread; it waits for the child.

#include <ostream>
#include <string>
#include <vector>

#include "scene/level.h"

namespace sandbox::app {

// The program run as the child: by default this program (/proc/self/exe);
// a host that is not `sandbox` (the Python module) names the sandbox binary.
// Set before any load, from one thread.
void SetIsolatedLoader(const std::string& program);

// Throws scene::LevelError when the child fails, naming the file.
void CheckLoadsInIsolation(const std::string& file, const scene::AssetConversion& conversion);

// The child: `sandbox __load-level FILE [--up AXIS] [--unit-scale M]`. Writes
// "started", "reading PATH" before each file, then "ok" or "error MESSAGE",
// to `out`.
int RunLoadLevelChild(const std::vector<std::string>& args, std::ostream& out);

}  // namespace sandbox::app
