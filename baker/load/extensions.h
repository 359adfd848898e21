/*
 * What lmbake does with each glTF extension it knows (see extensions.c): implemented,
 * accepted with a warning because it only changes what a diffuse baker does not read, or an
 * alternative image format accepted when the textures lmbake reads keep a fallback image. An
 * extension not listed is refused when a file requires it (preflight.c).
 */
#ifndef LMBAKE_EXTENSIONS_H
#define LMBAKE_EXTENSIONS_H

typedef enum lmb_ext_support {
    LMB_EXT_SUPPORTED = 0, /* implemented */
    LMB_EXT_IGNORED = 1,   /* accepted with a warning: `effect` says what the bake leaves out */
    LMB_EXT_IMAGE = 2      /* texture source format: accepted if the textures lmbake reads have a fallback `source` */
} lmb_ext_support;

typedef struct lmb_extension_info {
    const char *name;
    lmb_ext_support support;
    const char *effect; /* for the warning; NULL for supported ones */
} lmb_extension_info;

/* The entry for extension `name`, or NULL when lmbake does not know it. */
const lmb_extension_info *lmb_extension_find(const char *name);

#endif
