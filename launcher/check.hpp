#pragma once
// `fsi check`: a scene against the scene schema, in-process, without meshing or starting a solver
// (fsi/common/scene_schema.hpp).
#include <istream>
#include <string>
#include <utility>
#include <vector>

namespace fsi::launcher {

// `fsi check SCENE [--set k=v ...]`: prints "OK: SCENE (N keys checked)" on stdout and returns 0,
// or prints every problem as "file:line:col: message" on stderr and returns 1. `placed`: overrides
// ("key=value") with the place they were written ("file:line:col"), named in the problems (the
// study tool checks a study's cases this way). `json`: one JSON object on stdout instead
// ({"file", "keys_checked", "problems": [{"where", "message", "key", "text"}]}). A study is
// read by the study tool (fsi_study.py check), not here. `skip_sections`: sections an external
// solver reads (`fsi check --solid-command ...`, as `fsi run` skips them).
int check_file(const std::string& file, const std::vector<std::string>& overrides,
               const std::vector<std::pair<std::string, std::string>>& placed = {}, bool json = false,
               const std::vector<std::string>& skip_sections = {});

// Many checks of one scene in one process (the study tool's cases): `cases` is a JSON list of
// cases, each a list of [assignment, where] on top of `overrides` and `placed`; prints one JSON
// list of the results (as --json prints one). Returns 1 only when `cases` is not such a list.
int check_cases(const std::string& file, const std::vector<std::string>& overrides,
                const std::vector<std::pair<std::string, std::string>>& placed, std::istream& cases);

// A study file (top-level `study` or `vary`) rather than a scene.
bool is_study_file(const std::string& file);

// The check `fsi run` does first: prints the problems on stderr, returns false if any (and
// them, one a line, in `problems`). `skip_sections`: sections an external solver
// (--solid-command / --fluid-command) reads.
bool check_before_run(const std::string& scene, const std::vector<std::string>& overrides,
                      const std::vector<std::string>& skip_sections, std::string& problems);

}  // namespace fsi::launcher
