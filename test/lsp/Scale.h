// A class as a new user writes it first: its control function takes pointers without saying how
// many elements they hold, which the Vulkan class needs to know, and its kernel's loop does not say
// either (two elements a thread; the language server test fixes it).
#pragma once

class Scale {
public:
  virtual ~Scale() = default;
  virtual void Run(int n, const float* in, float* out);

protected:
  void kernel1D_Scale(int n, const float* in, float* out);
  float m_factor = 2.0f;
};
