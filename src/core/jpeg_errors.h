// libjpeg's error handling for whitted's JPEG reader (src/importers/image_decode.cpp) and writer
// (src/core/image_files_display.cpp): errors leave the library call through a longjmp, with
// the library's message kept for the one error line.
#pragma once

#include <csetjmp>
#include <cstdio>  // jpeglib.h needs FILE

#include <jpeglib.h>

namespace whitted {

/// Set `cinfo.err = jpeg_std_error(&errors.mgr)` and `errors.mgr.error_exit = jpeg_error_exit`,
/// then `setjmp(errors.jump)` before the first library call that may fail.
struct JpegErrors {
    jpeg_error_mgr mgr;
    std::jmp_buf jump;
    char message[JMSG_LENGTH_MAX];
};

[[noreturn]] inline void jpeg_error_exit(j_common_ptr cinfo) {
    auto* e = reinterpret_cast<JpegErrors*>(cinfo->err);
    (*cinfo->err->format_message)(cinfo, e->message);
    std::longjmp(e->jump, 1);
}

}  // namespace whitted
