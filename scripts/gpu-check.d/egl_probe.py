#!/usr/bin/env python3
"""Prints what EGL offers headless programs: the client extensions, and for
each EGL device (EGL_EXT_device_enumeration) its vendor, version and
extensions, then the OpenGL renderer of a desktop GL context on the first
device (what skybake's GL code takes with SKYBAKE_EGL_PLATFORM=device).
Exit 1 when no device display initialises.

    scripts/gpu-check.d/egl_probe.py
"""
import ctypes
import ctypes.util
import sys

EGL_EXTENSIONS, EGL_VENDOR, EGL_VERSION = 0x3055, 0x3053, 0x3054
EGL_PLATFORM_DEVICE_EXT = 0x313F
EGL_OPENGL_API = 0x30A2
EGL_NONE = 0x3038
EGL_CONTEXT_MAJOR_VERSION, EGL_CONTEXT_MINOR_VERSION = 0x3098, 0x30FB
EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT = 0x30FD, 0x1
EGL_DRM_DEVICE_FILE_EXT = 0x3233
GL_VENDOR, GL_RENDERER, GL_VERSION = 0x1F00, 0x1F01, 0x1F02


def load(names):
    for n in names:
        try:
            return ctypes.CDLL(n)
        except OSError:
            pass
    return None


def main():
    egl = load(["libEGL.so.1", ctypes.util.find_library("EGL") or "libEGL.so"])
    if egl is None:
        print("egl: libEGL.so.1 not found (the GL loader packages libegl1 and libglvnd0 are missing)")
        return 1
    egl.eglQueryString.restype = ctypes.c_char_p
    egl.eglQueryString.argtypes = [ctypes.c_void_p, ctypes.c_int]
    egl.eglGetProcAddress.restype = ctypes.c_void_p
    egl.eglGetProcAddress.argtypes = [ctypes.c_char_p]
    client = (egl.eglQueryString(None, EGL_EXTENSIONS) or b"").decode()
    print("egl client extensions:", client)
    if "EGL_EXT_device_enumeration" not in client.split():
        print("egl: no EGL_EXT_device_enumeration (no vendor library loaded: check __EGL_VENDOR_LIBRARY_FILENAMES)")
        return 1

    def proc(name, restype, *argtypes):
        addr = egl.eglGetProcAddress(name.encode())
        return ctypes.CFUNCTYPE(restype, *argtypes)(addr) if addr else None

    query_devices = proc("eglQueryDevicesEXT", ctypes.c_uint, ctypes.c_int, ctypes.POINTER(ctypes.c_void_p),
                         ctypes.POINTER(ctypes.c_int))
    query_device_string = proc("eglQueryDeviceStringEXT", ctypes.c_char_p, ctypes.c_void_p, ctypes.c_int)
    platform_display = proc("eglGetPlatformDisplayEXT", ctypes.c_void_p, ctypes.c_int, ctypes.c_void_p,
                            ctypes.c_void_p)
    devices = (ctypes.c_void_p * 16)()
    count = ctypes.c_int(0)
    if not query_devices or not query_devices(16, devices, ctypes.byref(count)):
        print("egl: eglQueryDevicesEXT failed")
        return 1
    print("egl devices:", count.value)
    egl.eglInitialize.argtypes = [ctypes.c_void_p, ctypes.POINTER(ctypes.c_int), ctypes.POINTER(ctypes.c_int)]
    egl.eglTerminate.argtypes = [ctypes.c_void_p]
    first = None
    for i in range(count.value):
        ext = query_device_string(devices[i], EGL_EXTENSIONS) if query_device_string else None
        drm = query_device_string(devices[i], EGL_DRM_DEVICE_FILE_EXT) if ext and b"EGL_EXT_device_drm" in ext else None
        dpy = platform_display(EGL_PLATFORM_DEVICE_EXT, devices[i], None)
        major, minor = ctypes.c_int(0), ctypes.c_int(0)
        if not dpy or not egl.eglInitialize(dpy, ctypes.byref(major), ctypes.byref(minor)):
            print(f"egl device {i}: does not initialise (extensions: {(ext or b'').decode()})")
            continue
        vendor = (egl.eglQueryString(dpy, EGL_VENDOR) or b"?").decode()
        version = (egl.eglQueryString(dpy, EGL_VERSION) or b"?").decode()
        print(f"egl device {i}: vendor {vendor}, EGL {version}, drm {drm.decode() if drm else '-'}, "
              f"extensions {(ext or b'').decode()}")
        if first is None:
            first = dpy
        else:
            egl.eglTerminate(dpy)
    if first is None:
        print("egl: no device display initialised")
        return 1
    # A desktop OpenGL 3.3 core context without a surface, as skybake makes one.
    egl.eglBindAPI.argtypes = [ctypes.c_uint]
    egl.eglBindAPI(EGL_OPENGL_API)
    egl.eglCreateContext.restype = ctypes.c_void_p
    egl.eglCreateContext.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p, ctypes.POINTER(ctypes.c_int)]
    egl.eglMakeCurrent.argtypes = [ctypes.c_void_p] * 4
    attribs = (ctypes.c_int * 7)(EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 3,
                                 EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE)
    ctx = egl.eglCreateContext(first, None, None, attribs)
    if not ctx or not egl.eglMakeCurrent(first, None, None, ctx):
        print("gl: no OpenGL 3.3 core context without a configuration (EGL_KHR_no_config_context)")
        return 0
    gl = load(["libOpenGL.so.0", "libGL.so.1"])
    if gl is not None:
        gl.glGetString.restype = ctypes.c_char_p
        gl.glGetString.argtypes = [ctypes.c_uint]
        for name, e in (("vendor", GL_VENDOR), ("renderer", GL_RENDERER), ("version", GL_VERSION)):
            print(f"gl {name}: {(gl.glGetString(e) or b'?').decode()}")
    egl.eglMakeCurrent(first, None, None, None)
    egl.eglTerminate(first)
    return 0


if __name__ == "__main__":
    sys.exit(main())
