/* The summary writer the closed-loop images on the target share (pil_summary.c). */
#ifndef PIL_SUMMARY_H
#define PIL_SUMMARY_H

#include <stdio.h>

#include "sil/metrics.h"

/** Writes @p s as JSON to @p f; @p target names the image (e.g. "qemu mps2-an386 (Cortex-M4F)"). */
void pil_write_summary(FILE *f, const char *target, const sil_summary_t *s, double duration_s, int substeps);

#endif /* PIL_SUMMARY_H */
