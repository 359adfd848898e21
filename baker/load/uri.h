/*
 * Where a glTF URI may point (issue 15: file access confined to the input's folder). A URI is
 * embedded (data:), a relative path that stays inside the input's folder (after percent-
 * decoding and resolving "." and ".."), or refused: another scheme (file:, http:, ...), an
 * absolute path, a path whose ".." leaves the folder, or one with a NUL, a backslash or a
 * drive letter. Buffers that are refused are errors; images are skipped with a warning.
 * The check is on the text; lmb_path_inside also checks where the file really is
 * (symbolic links), since only the filesystem knows that.
 */
#ifndef LMBAKE_URI_H
#define LMBAKE_URI_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef enum lmb_uri_kind {
    LMB_URI_INSIDE = 0,   /* a relative path inside the input's folder */
    LMB_URI_EMBEDDED,     /* data: */
    LMB_URI_SCHEME,       /* another scheme: file:, http:, ... */
    LMB_URI_ABSOLUTE,     /* /etc/passwd, C:\..., //host/... */
    LMB_URI_ESCAPES,      /* ../ leaves the input's folder */
    LMB_URI_MALFORMED     /* empty, a bad %-escape, a NUL or a backslash */
} lmb_uri_kind;

/* Classifies uri; for LMB_URI_INSIDE, `relative` (size bytes) receives the decoded, normalised
 * path ("textures/wall.png"; never "..", never absolute). */
lmb_uri_kind lmb_uri_check(const char *uri, char *relative, size_t size);

/* Why a URI of this kind is refused, for messages ("uses the scheme ..." etc.). */
const char *lmb_uri_refusal(lmb_uri_kind kind);

/* 1 when path, symbolic links followed, is a regular file inside folder (resolved the same
 * way); its resolved form then goes into `resolved` (size bytes). 0 otherwise. */
int lmb_path_inside(const char *folder, const char *path, char *resolved, size_t size);

#ifdef __cplusplus
}
#endif

#endif
