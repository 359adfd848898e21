/*
 * Runs the preview's node scripts (the .mjs files in tools/preview): the browser side of lmbake lives in
 * JavaScript (three.js, playwright-core), the CLI only finds and starts it. The project root
 * is $LMBAKE_ROOT, else the folder above the one holding the lmbake executable (build/lmbake).
 */
#ifndef LMBAKE_NODE_TOOL_H
#define LMBAKE_NODE_TOOL_H

#include <stddef.h>

/* Path of tools/preview/<script> into out; 0 with a message on stderr when it is missing. */
int node_tool_path(const char *script, char *out, size_t size);

/* Replaces the process with `node script args...` (returns only on failure, with a message). */
int node_tool_exec(const char *script_path, char *const args[]);

/* Runs `node script args...` and waits; returns its exit code, or -1 when it cannot start. */
int node_tool_run(const char *script_path, char *const args[]);

#endif
