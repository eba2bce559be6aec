//! The real GL behind the interposer: functions looked up with
//! `dlsym(RTLD_NEXT, name)`, i.e. in the libraries loaded after this one
//! (the system's libGL and libEGL), and where the program never linked
//! them but opened them privately (`dlopen` with `RTLD_LOCAL`, as Qt's GLX plugin
//! does) in that library itself, opened by name. A function found in
//! neither is missing: its calls do nothing, it is named once on stderr,
//! and `glXGetProcAddress` answers null for it, as GL does for an unknown
//! name; never a null pointer called.

use core::ffi::{CStr, c_void};
use std::sync::OnceLock;

/// A real GL function, looked up on first use.
pub(crate) struct RealFn {
    name: &'static CStr,
    ptr: OnceLock<usize>,
}

impl RealFn {
    pub(crate) const fn new(name: &'static CStr) -> Self {
        Self { name, ptr: OnceLock::new() }
    }

    /// The function's address, or `None` if no later library has it.
    pub(crate) fn get(&self) -> Option<*const c_void> {
        let p = *self.ptr.get_or_init(|| {
            let p = lookup(self.name);
            if p == 0 {
                eprintln!(
                    "rt-gl: {} is not in the system's GL; its calls are dropped",
                    self.name.to_string_lossy()
                );
            }
            p
        });
        (p != 0).then_some(p as *const c_void)
    }
}

/// The real GL's `name`: the next definition after this library, else
/// libGL's own (opened privately by the program), else, for names that
/// are not GLX's, what GLX answers (extensions a libGL may not export).
fn lookup(name: &CStr) -> usize {
    // SAFETY: `name` is a NUL-terminated string; RTLD_NEXT asks the
    // dynamic linker for the next definition after this library.
    let p = unsafe { libc::dlsym(libc::RTLD_NEXT, name.as_ptr()) } as usize;
    if p != 0 {
        return p;
    }
    let egl = name.to_bytes().starts_with(b"egl");
    if let Some(lib) = if egl { system_egl() } else { system_gl() } {
        // SAFETY: a handle from dlopen and a NUL-terminated name; the
        // lookup is in that library and its dependencies, not this one.
        let p = unsafe { libc::dlsym(lib as *mut c_void, name.as_ptr()) } as usize;
        if p != 0 {
            return p;
        }
    }
    if egl || name.to_bytes().starts_with(b"glX") {
        return 0;
    }
    // SAFETY: a NUL-terminated name.
    unsafe { glXGetProcAddressARB(name.as_ptr().cast()) }.map_or(0, |f| f as usize)
}

/// The system's libGL, as a handle of its own: the one the program
/// loaded (privately or not), else opened here; `None` if there is none.
fn system_gl() -> Option<usize> {
    static GL: OnceLock<usize> = OnceLock::new();
    system_library(&GL, &[c"libGL.so.1", c"libGL.so"])
}

/// The system's libEGL, as [`system_gl`] finds libGL.
fn system_egl() -> Option<usize> {
    static EGL: OnceLock<usize> = OnceLock::new();
    system_library(&EGL, &[c"libEGL.so.1", c"libEGL.so"])
}

/// The first of `names` already loaded, else the first that opens.
fn system_library(cell: &OnceLock<usize>, names: &[&CStr]) -> Option<usize> {
    let h = *cell.get_or_init(|| {
        for name in names {
            for flags in [
                libc::RTLD_LAZY | libc::RTLD_LOCAL | libc::RTLD_NOLOAD,
                libc::RTLD_LAZY | libc::RTLD_LOCAL,
            ] {
                // SAFETY: a NUL-terminated library name; RTLD_LOCAL keeps
                // its symbols out of the global scope.
                let h = unsafe { libc::dlopen(name.as_ptr(), flags) } as usize;
                if h != 0 {
                    return h;
                }
            }
        }
        0
    });
    (h != 0).then_some(h)
}

/// Declares `pub(crate) unsafe fn name(args) -> ret` calling the real
/// function (doing nothing, returning the default, if it is missing).
macro_rules! real_fns {
    ($($name:ident($($a:ident: $t:ty),*) $(-> $r:ty)?;)*) => {
        $(
            #[allow(non_snake_case)]
            pub(crate) unsafe fn $name($($a: $t),*) $(-> $r)? {
                static REAL: RealFn = RealFn::new(
                    // SAFETY: the literal ends in its only NUL.
                    unsafe { CStr::from_bytes_with_nul_unchecked(concat!(stringify!($name), "\0").as_bytes()) },
                );
                match REAL.get() {
                    Some(p) => {
                        // SAFETY: the symbol of that name in the system's
                        // GL has this C signature (the GL specification's).
                        let f: unsafe extern "C" fn($($t),*) $(-> $r)? = unsafe { core::mem::transmute(p) };
                        // SAFETY: the caller passes arguments valid for it.
                        unsafe { f($($a),*) }
                    }
                    None => Default::default(),
                }
            }
        )*
    };
}

real_fns! {
    glPushAttrib(mask: u32);
    glPopAttrib();
    glPushClientAttrib(mask: u32);
    glPopClientAttrib();
    glMatrixMode(mode: u32);
    glPushMatrix();
    glPopMatrix();
    glLoadIdentity();
    glDisable(cap: u32);
    glEnable(cap: u32);
    glAlphaFunc(func: u32, reference: f32);
    glPixelStorei(pname: u32, param: i32);
    glPixelZoom(x: f32, y: f32);
    glWindowPos2i(x: i32, y: i32);
    glDrawPixels(w: i32, h: i32, format: u32, ty: u32, data: *const c_void);
    glReadPixels(x: i32, y: i32, w: i32, h: i32, format: u32, ty: u32, data: *mut c_void);
    glReadBuffer(mode: u32);
    glGetBooleanv(pname: u32, data: *mut u8);
    glGetIntegerv(pname: u32, data: *mut i32);
    glXSwapBuffers(dpy: *mut c_void, drawable: u64);
    eglSwapBuffers(dpy: *mut c_void, surface: *mut c_void) -> u32;
    eglGetProcAddress(name: *const u8) -> Option<unsafe extern "C" fn()>;
    glXGetProcAddress(name: *const u8) -> Option<unsafe extern "C" fn()>;
    glXGetProcAddressARB(name: *const u8) -> Option<unsafe extern "C" fn()>;
}
