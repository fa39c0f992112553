#!/usr/bin/env python3
"""Checks that the library graph is the one the sources include.

Usage: check_library_graph.py SOURCE_DIR GRAPH_FILE

GRAPH_FILE (written by CMake, top CMakeLists.txt) has one line per project
library: its name, its folder (relative to SOURCE_DIR) and what it links,
tab-separated, the links ';'-separated. Every project library must link
exactly the project libraries whose headers its folder's files include
(#include "src/..." and "colmap_ext/..."), and the links must not form a
cycle. Prints every violation and exits 1 if there is one.
"""
import os
import re
import sys

INCLUDE = re.compile(r'^\s*#\s*include\s+"((?:src|colmap_ext)/[^"]+)"')


def read_graph(path):
    libraries = {}  # name -> (folder, [links])
    with open(path) as graph:
        for line in graph:
            fields = line.rstrip("\n").split("\t")
            if len(fields) != 3:
                continue
            name, folder, links = fields
            libraries[name] = (folder, [link for link in links.split(";") if link])
    return libraries


def included_folders(source_dir, folder):
    """Per folder included by the folder's files, the first file and header."""
    included = {}
    folder_path = os.path.join(source_dir, folder)
    for file_name in sorted(os.listdir(folder_path)):
        if not file_name.endswith((".h", ".cc")):
            continue
        file_path = os.path.join(folder, file_name)
        with open(os.path.join(source_dir, file_path)) as source:
            for line in source:
                match = INCLUDE.match(line)
                if match:
                    header_folder = os.path.dirname(match.group(1))
                    if header_folder != folder:
                        included.setdefault(header_folder,
                                            (file_path, match.group(1)))
    return included


def find_cycle(links):
    """A cycle of the graph name -> project links, as a list, or None."""
    state = {}  # name -> 1 on the current path, 2 done

    def visit(name, path):
        state[name] = 1
        for link in links[name]:
            if state.get(link) == 1:
                return path[path.index(link):] + [link]
            if link not in state:
                cycle = visit(link, path + [link])
                if cycle:
                    return cycle
        state[name] = 2
        return None

    for name in sorted(links):
        if name not in state:
            cycle = visit(name, [name])
            if cycle:
                return cycle
    return None


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    source_dir, graph_path = sys.argv[1], sys.argv[2]
    libraries = read_graph(graph_path)
    library_of_folder = {folder: name for name, (folder, _) in libraries.items()}
    errors = []
    project_links = {}
    for name, (folder, links) in sorted(libraries.items()):
        linked = {link for link in links if link in libraries}
        project_links[name] = sorted(linked)
        needed = set()
        for header_folder, (file_path, header) in sorted(
                included_folders(source_dir, folder).items()):
            dependency = library_of_folder.get(header_folder)
            if dependency is None:
                errors.append(f"{file_path} includes {header}, which is in no "
                              "library")
                continue
            needed.add(dependency)
            if dependency not in linked:
                errors.append(f"{file_path} includes {header}, but {name} does "
                              f"not link {dependency}")
        for link in sorted(linked - needed):
            errors.append(f"{name} links {link}, but no file of {folder} "
                          f"includes a header of {libraries[link][0]}")
    cycle = find_cycle(project_links)
    if cycle:
        errors.append("the libraries link in a cycle: " + " -> ".join(cycle))
    for error in errors:
        print(f"library graph: ERROR: {error}", file=sys.stderr)
    if errors:
        print("library graph: the links are in rig_calibrator_add_library's "
              "DEPENDS (src/CMakeLists.txt, colmap_ext/CMakeLists.txt)",
              file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
