// The paper's spelling of the image header ("Image2d.h", as kernel_slicer's samples include it):
// the same LiteImage::Image2D, Sampler and Texture2D as Image2D.h. It lives in a folder of its own
// so that the two names never meet in one folder of a case-insensitive file system.
#pragma once
#include "../Image2D.h"
