#pragma once
// `fsi check`: a scene (or a study's scene with its fixed and varied keys) against the scene
// schema, in-process, without meshing or starting a solver (fsi/common/scene_schema.hpp).
#include <string>
#include <vector>

namespace fsi::launcher {

// `fsi check FILE [--set k=v ...]`: prints "OK: FILE (N keys checked)" on stdout and returns 0,
// or prints every problem as "file:line:col: message" on stderr and returns 1. FILE is a scene,
// or a study (top-level `study` or `vary`): its scene with `fixed` as overrides, and every
// scene key it varies (`vary`, `zip`, `derived`).
int check_file(const std::string& file, const std::vector<std::string>& overrides);

// The check `fsi run` does first: prints the problems on stderr, returns false if any (and
// them, one a line, in `problems`). `skip_sections`: sections an external solver
// (--solid-command / --fluid-command) reads.
bool check_before_run(const std::string& scene, const std::vector<std::string>& overrides,
                      const std::vector<std::string>& skip_sections, std::string& problems);

}  // namespace fsi::launcher
