//! An interpreter of naga IR in f64 with bounded time and memory.
//!
//! bv evaluates user BRDF shaders (GLSL or WGSL, translated by naga's front
//! ends into a [`naga::Module`]) on the CPU with this crate: [`Program::new`]
//! validates a module and compiles its functions once; [`Program::call`] runs
//! one of them on argument [`Value`]s. Floats are evaluated in f64 whatever
//! width the shader declares (literals keep the f32 value naga parsed);
//! 32-bit integers wrap like WGSL. Every call is bounded by [`Limits`]: a
//! step budget (an endless loop comes back as [`InterpError::StepBudget`]),
//! a call depth and a memory size (a huge local array is refused with
//! [`InterpError::Memory`] before anything is allocated).
//!
//! Calls are independent: a call starts from the module-scope values set with
//! [`Program::set_global`], and what it writes to them is dropped when it
//! returns. [`Program`] is `Send + Sync`; many threads may call at once.
//!
//! ```
//! use bv_interp::{Limits, Program, Value};
//!
//! let src = "var<private> k: f32 = 2.0;
//!            fn f(v: vec3<f32>) -> f32 { return k * dot(v, v); }";
//! let mut p = Program::new(naga::front::wgsl::parse_str(src).unwrap()).unwrap();
//! p.set_global("k", Value::f(0.5)).unwrap();
//! let r = p.call("f", &[Value::vec3(1.0, 2.0, 2.0)], &Limits::default());
//! assert_eq!(r, Ok(Value::f(4.5)));
//! ```
//!
//! # Semantics
//!
//! - Arithmetic follows WGSL where GLSL leaves things undefined: integer
//!   `x / 0 == x`, `x % 0 == 0`, `i32::MIN / -1 == i32::MIN`; shifts use the
//!   low five bits of the amount; float-to-integer conversions saturate (NaN
//!   to 0); float `%` truncates (GLSL's floored `mod` arrives already
//!   expanded by naga's front end); `round` is ties-to-even.
//! - `min`, `max`, `clamp` and `saturate` are IEEE minNum/maxNum: a NaN
//!   operand loses (`saturate(NaN) == 0`), as on GPUs.
//! - A run-time index out of range is clamped to the last element (naga's
//!   `Restrict` bounds-check policy).
//! - Literals and constant sub-expressions are what naga's front ends made of
//!   them: its constant evaluator folds constant expressions in the declared
//!   type, so `2.0 * 3.14159` in an f32 shader is one f32 constant. Only the
//!   run-time arithmetic is f64.
//! - Not evaluated (reported by [`Program::new`] as
//!   [`InterpError::Unsupported`]): textures and samplers, derivatives,
//!   atomics, barriers, workgroup and storage variables, runtime-sized arrays
//!   (`arrayLength`), ray queries, subgroup operations, cooperative matrices,
//!   16- and 64-bit integers, `quantizeToF16`, the `pack*`/`unpack*` and
//!   packed dot-product functions, overrides without a value. `discard`
//!   fails the call with [`InterpError::Kill`].
//! - One function's frame (locals plus intermediate values) is at most
//!   16 MiB whatever the limits say; a larger one fails every call with
//!   [`InterpError::Memory`] and is never allocated.

mod compile;
mod error;
mod exec;
mod ins;
mod layout;
mod math;
mod value;

use std::collections::HashMap;

use naga::{
    AddressSpace, TypeInner,
    valid::{Capabilities, ValidationFlags, Validator},
};

pub use error::InterpError;
pub use value::{Kind, Matrix, Value, Vector};

use compile::{Func, Globals};
use layout::Types;

/// Bounds on one [`Program::call`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limits {
    /// Statements and expressions a call may run (loop iterations count too).
    pub max_steps: u64,
    /// How deeply calls may nest below the called function (0: it may call
    /// no other function).
    pub max_call_depth: u32,
    /// Bytes of memory for module-scope variables, arguments, locals and
    /// intermediate values (8 bytes a component).
    pub max_memory_bytes: usize,
}

impl Default for Limits {
    /// A million steps (a few milliseconds; far more than any BRDF needs),
    /// 64 nested calls, 16 MiB.
    fn default() -> Self {
        Limits {
            max_steps: 1_000_000,
            max_call_depth: 64,
            max_memory_bytes: 16 * 1024 * 1024,
        }
    }
}

/// A validated, compiled module, ready to be called.
pub struct Program {
    module: naga::Module,
    types: Types,
    globals: Globals,
    funcs: Vec<Func>,
    by_name: HashMap<String, usize>,
}

impl Program {
    /// Validates `module` with naga's validator and compiles every function
    /// that is not an entry point. Fails with [`InterpError::Invalid`] for an
    /// invalid module and [`InterpError::Unsupported`] (naming the feature
    /// and the function) when a function uses something the interpreter
    /// cannot evaluate: textures, derivatives, atomics, 64-bit integers, …
    pub fn new(module: naga::Module) -> Result<Program, InterpError> {
        let info = Validator::new(ValidationFlags::all(), Capabilities::all())
            .validate(&module)
            .map_err(|e| InterpError::Invalid(e.emit_to_string("")))?;
        // Validation makes every offset the compiler computes consistent;
        // a panic would be an interpreter bug, reported rather than raised.
        std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            Program::compile(module, &info)
        }))
        .unwrap_or_else(|_| {
            Err(InterpError::Internal(
                "the interpreter failed while compiling the module".into(),
            ))
        })
    }

    fn compile(
        module: naga::Module,
        info: &naga::valid::ModuleInfo,
    ) -> Result<Program, InterpError> {
        let types = Types::new(&module.types);
        let globals = compile::globals(&module, info, &types)?;
        let mut funcs = Vec::with_capacity(module.functions.len());
        let mut by_name = HashMap::new();
        for (h, f) in module.functions.iter() {
            let func = compile::function(&module, info, &types, &globals, h)?;
            if let Some(name) = &f.name {
                by_name.entry(name.clone()).or_insert(funcs.len());
            }
            funcs.push(func);
        }
        Ok(Program {
            module,
            types,
            globals,
            funcs,
            by_name,
        })
    }

    /// The module (for callers that also emit WGSL from it).
    pub fn module(&self) -> &naga::Module {
        &self.module
    }

    /// The names of the callable functions, in the module's order.
    pub fn function_names(&self) -> impl Iterator<Item = &str> {
        self.funcs.iter().map(|f| f.name.as_str())
    }

    /// Sets the initial value of a module-scope variable (address space
    /// `private`, `uniform` or immediate data) for every later call. A member
    /// of a uniform block may be named directly, as GLSL code refers to the
    /// members of an unnamed block. An unknown name or a value of another
    /// type is an error.
    pub fn set_global(&mut self, name: &str, value: Value) -> Result<(), InterpError> {
        let m = &self.module;
        let settable = |space| {
            matches!(
                space,
                AddressSpace::Private | AddressSpace::Uniform | AddressSpace::Immediate
            )
        };
        let mut target = None;
        for (h, var) in m.global_variables.iter() {
            if var.name.as_deref() == Some(name) && settable(var.space) {
                target = Some((h, var.ty, 0u64));
                break;
            }
        }
        if target.is_none() {
            // A member of a block (GLSL `uniform Params { float n; };`).
            'outer: for (h, var) in m.global_variables.iter() {
                if !settable(var.space) {
                    continue;
                }
                if let TypeInner::Struct { members, .. } = &m.types[var.ty].inner {
                    for (i, mem) in members.iter().enumerate() {
                        if mem.name.as_deref() == Some(name) {
                            let off = self.types.member_offset(var.ty, i).unwrap_or(0);
                            target = Some((h, mem.ty, off));
                            break 'outer;
                        }
                    }
                }
            }
        }
        let (h, ty, off) = target.ok_or_else(|| InterpError::UnknownGlobal(name.to_string()))?;
        let base = self.globals.var_off[h.index()]
            .ok_or_else(|| InterpError::UnknownGlobal(name.to_string()))?;
        let at = (u64::from(base) + off) as usize;
        let n = self.types.cells(ty) as usize;
        let cells = &mut self.globals.image[at..at + n];
        layout::encode(&m.types, &self.types, ty, &value, cells, &|| {
            format!("the global `{name}`")
        })
    }

    /// Calls the function `name` with `args`, within `limits`, and returns
    /// its result ([`Value::Void`] for a function without one).
    pub fn call(&self, name: &str, args: &[Value], limits: &Limits) -> Result<Value, InterpError> {
        let &fi = self
            .by_name
            .get(name)
            .ok_or_else(|| InterpError::UnknownFunction(name.to_string()))?;
        let f = &self.funcs[fi];
        if args.len() != f.params.len() {
            return Err(InterpError::Type {
                what: format!("the arguments of `{name}`"),
                expected: format!("{} arguments", f.params.len()),
                found: format!("{}", args.len()),
            });
        }
        if f.params.iter().any(|p| p.pointer) {
            return Err(InterpError::Type {
                what: format!("the arguments of `{name}`"),
                expected: "a pointer (only functions taking values can be called)".into(),
                found: "values".into(),
            });
        }
        exec::with_memory(|mem| {
            // The vector keeps its length between calls (what a previous
            // call left is overwritten before it is read), so only the
            // module-scope image and the frame templates are copied.
            let fb = self.globals.image.len();
            if mem.len() < fb {
                mem.resize(fb, 0.0);
            }
            mem[..fb].copy_from_slice(&self.globals.image);
            let mut machine = exec::Machine {
                funcs: &self.funcs,
                mem,
                steps: 0,
                depth: 0,
                limits: *limits,
            };
            machine.enter(f, fb)?;
            for (k, (p, a)) in f.params.iter().zip(args).enumerate() {
                let n = self.types.cells(p.ty) as usize;
                let d = fb + p.off as usize;
                layout::encode(
                    &self.module.types,
                    &self.types,
                    p.ty,
                    a,
                    &mut machine.mem[d..d + n],
                    &|| format!("argument {} of `{name}`", k + 1),
                )?;
            }
            // The compiler keeps every offset inside its frame; catching a
            // panic anyway turns an interpreter bug into an error instead
            // of taking the application down.
            let run = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                machine.block(f, &f.body, fb)
            }));
            match run {
                Ok(r) => r?,
                Err(_) => {
                    return Err(InterpError::Internal(format!(
                        "the interpreter failed while running `{name}`"
                    )));
                }
            };
            Ok(match f.ret {
                Some(t) => {
                    let n = self.types.cells(t) as usize;
                    layout::decode(
                        &self.module.types,
                        &self.types,
                        Some(t),
                        &self.module.types[t].inner,
                        &machine.mem[fb..fb + n],
                    )
                }
                None => Value::Void,
            })
        })
    }
}
