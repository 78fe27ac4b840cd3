#!/usr/bin/env python3
"""Every scene key is declared once, beside the code that reads it.

Fails when
  - a scene key is declared (a call of the schema's builders: number("...", ...), section(...),
    ...) outside the declaration files: common/src/standalone.cpp (time) and the components'
    *_keys.cpp files;
  - a reader writes a default of its own: ConfigSection's get<T>("key", fallback) anywhere but
    in the schema's own code (defaults come from the declarations through schema::Reader);
  - a declaration file declares a key of another section than its component's.
Usage: scene_keys_declared_once.py SOURCE_DIR
"""
import pathlib
import re
import sys

root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".")
folders = ["common", "coupler", "fluid_server", "solid_server", "launcher", "protocol", "transport", "bench"]
builders = ("number|integer|boolean|text|choice|vector2|number_or_vector2|names|string_list|int_list|point_pair|"
            "section|section_list|named_map|selector_section")
declaration = re.compile(r'(?<![\w.:>])(?:schema::)?(' + builders + r')\(\s*"')
default_in_reader = re.compile(r'\bget<[^;]*?>\("[A-Za-z_]+",\s*[^)]')
# The declaration files and the section each declares.
declaration_files = {
    "common/src/standalone.cpp": "time",
    "coupler/src/coupling_keys.cpp": "coupling",
    "solid_server/src/sdof_keys.cpp": "solid",
    "solid_server/src/solid_keys.cpp": "solid",
    "solid_server/core/src/fem_solid_keys.cpp": "solid",
    "fluid_server/src/surrogate_keys.cpp": "fluid",
    "fluid_server/src/fluid_keys.cpp": "fluid",
    "fluid_server/core/src/navier_stokes_keys.cpp": "fluid",
    # the point models' interface (dimension, surface), in both the solid and the fluid section
    "common/src/model_interface_keys.cpp": "interface",
    # every solver section's `substeps` (waveform iterations), read by the coupler
    "common/src/window_keys.cpp": "interface",
}
# The schema's own code (the builders, the checker, Scene's scene/description) may use both.
schema_files = {"common/src/scene_declare.cpp", "common/src/scene_schema.cpp", "common/src/config.cpp",
                "common/include/fsi/common/config.hpp", "common/include/fsi/common/scene_schema.hpp",
                "common/include/fsi/common/scene_reader.hpp", "common/src/scene_reader.cpp"}
component_of = {"time": "common/", "interface": "common/", "coupling": "coupler/", "solid": "solid_server/", "fluid": "fluid_server/"}

problems = []
declared_in = []
for folder in folders:
    for path in sorted((root / folder).rglob("*")):
        if path.suffix not in (".cpp", ".hpp") or not path.is_file():
            continue
        rel = path.relative_to(root).as_posix()
        if rel in schema_files:
            continue
        text = path.read_text(encoding="utf-8")
        code = re.sub(r"//[^\n]*", "", text)  # comments may name keys
        if "scene_schema.hpp" in text or "scene_reader.hpp" in text or "schema::" in text:
            for m in declaration.finditer(code):
                line = code.count("\n", 0, m.start()) + 1
                if rel not in declaration_files:
                    problems.append(f"{rel}:{line}: a scene key declared outside the declaration files "
                                    f"({m.group(0)}...)")
                else:
                    declared_in.append(rel)
        for m in default_in_reader.finditer(code):
            line = code.count("\n", 0, m.start()) + 1
            problems.append(f"{rel}:{line}: a reader writes a default of its own ({m.group(0)}...); declare it "
                            "and read it through schema::Reader")

for rel, section in declaration_files.items():
    if not (root / rel).is_file():
        problems.append(f"{rel}: the declaration file is missing")
        continue
    if not rel.startswith(component_of[section]):
        problems.append(f"{rel}: declares '{section}' keys outside its component ({component_of[section]})")
    if rel not in declared_in:
        problems.append(f"{rel}: declares no key (a stale entry in this test's list?)")

if problems:
    print("\n".join(problems))
    sys.exit(1)
print(f"{len(declared_in)} declarations, all in the {len(declaration_files)} declaration files; no reader "
      "writes a default of its own")
