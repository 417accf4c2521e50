//! Compiling naga IR into the interpreter's frames, instructions and
//! statements, once per module.
//!
//! Every expression gets a run of cells in its function's frame (or aliases
//! part of another's: a member of a value, an identity conversion). A frame is
//! `[result | arguments | local variables | expressions]`. Expressions whose
//! operands are all constant are evaluated here, into the frame's template,
//! and cost nothing per call; this is also what gives local variables their
//! constant initial values. Pointers are resolved to places: static offsets
//! where naga's IR allows it, a run-time address cell otherwise.
//!
//! `expr` compiles expressions, `stmt` statements.

mod expr;
mod single_store;
mod stmt;

use naga::{
    ArraySize, Expression, Function, Handle, Literal, Module, Type, TypeInner,
    proc::TypeResolution,
    valid::{FunctionInfo, ModuleInfo},
};

use crate::{
    InterpError, Kind,
    ins::{self, Ins, Place},
    layout::{Types, kind_of},
};

/// The largest frame (or module-scope memory) compiled, in cells: 16 MiB.
/// Larger ones are refused with [`InterpError::Memory`] when called, so a
/// declaration of a huge local array never allocates.
pub(crate) const MAX_CELLS: u64 = 2 * 1024 * 1024;

/// A compiled statement.
#[derive(Debug)]
pub(crate) enum Stmt {
    /// Runs the instructions `start..end` of the function's code (the
    /// expressions of `Emit`s and `Store`s in a row); the third field is
    /// their cost in steps.
    Run(u32, u32, u64),
    If {
        cond: u32,
        accept: Box<[Stmt]>,
        reject: Box<[Stmt]>,
    },
    Switch {
        selector: u32,
        cases: Box<[Case]>,
    },
    Loop {
        body: Box<[Stmt]>,
        continuing: Box<[Stmt]>,
        break_if: Option<u32>,
    },
    Break,
    Continue,
    /// Copies the value (offset, cells) to the frame's result, and returns.
    Return(Option<(u32, u32)>),
    Kill,
    Call {
        func: u32,
        args: Box<[Arg]>,
        result: Option<(u32, u32)>,
    },
}

/// One `switch` case; `value` is `None` for `default`.
#[derive(Debug)]
pub(crate) struct Case {
    pub(crate) value: Option<f64>,
    pub(crate) body: Box<[Stmt]>,
    pub(crate) fall_through: bool,
}

/// A call argument: a value's cells, or a pointer.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Arg {
    Val { off: u32, n: u32 },
    Ptr(Place),
}

/// A parameter of a compiled function.
#[derive(Debug)]
pub(crate) struct Param {
    pub(crate) off: u32,
    pub(crate) ty: Handle<Type>,
    pub(crate) pointer: bool,
}

/// A compiled function.
#[derive(Debug)]
pub(crate) struct Func {
    pub(crate) name: String,
    /// Frame cells, or the bytes a too-large frame would need.
    pub(crate) frame: Result<u32, usize>,
    /// The frame's initial cells: the result, arguments, local variables
    /// (zero or their constant initial value) and every constant
    /// expression. The cells after it need no initial value.
    pub(crate) template: Box<[f64]>,
    pub(crate) ins: Box<[Ins]>,
    pub(crate) body: Box<[Stmt]>,
    pub(crate) params: Box<[Param]>,
    pub(crate) ret: Option<Handle<Type>>,
}

/// Module-scope memory: constant values and variables.
pub(crate) struct Globals {
    /// Cells of the module's constant expressions (the values of constants,
    /// overrides and variable initialisers).
    pub(crate) pool: Vec<f64>,
    /// Where each constant expression's value lies in `pool`.
    pub(crate) pool_loc: Vec<Loc>,
    /// The initial cells of the module-scope variables (absolute addresses
    /// `0..len` of every call's memory).
    pub(crate) image: Vec<f64>,
    /// The address of each module-scope variable, when it has memory.
    pub(crate) var_off: Vec<Option<u32>>,
}

/// Where an expression's value is.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Loc {
    /// Not compiled (never referenced before its definition in valid IR).
    Unset,
    /// Cells at this offset.
    Val(u32),
    /// A pointer.
    Place(Place),
    /// A texture, sampler or other resource handle (no cells).
    Opaque,
}

/// Builds the compile-time state shared by the constant pool and functions.
struct Cx<'a> {
    m: &'a Module,
    types: &'a Types,
    /// Where errors are said to be.
    fname: String,
    /// The function being compiled (`None` for module-scope expressions).
    func: Option<(&'a Function, &'a FunctionInfo)>,
    minfo: &'a ModuleInfo,
    globals: Option<&'a Globals>,
    /// The frame's (or the pool's) cells as compilation leaves them.
    mem: Vec<f64>,
    loc: Vec<Loc>,
    konst: Vec<bool>,
    /// Instructions of the expressions, in arena order.
    ins: Vec<Ins>,
    ins_at: Vec<u32>,
    /// The function's code: the instructions of each `Emit` and each
    /// `Store` in statement order, so that straight-line statements run as
    /// one [`Stmt::Run`].
    code: Vec<Ins>,
    local_off: Vec<u32>,
    /// An upper bound of the cells the frame needs, for the message when it
    /// is too large.
    estimate: u64,
    /// The end of the cells that must start each call with their compiled
    /// value: local variables and constant expressions. Cells past it are
    /// always written before they are read (naga's IR uses an expression
    /// only after it was emitted), so they need no initialisation.
    init_end: u64,
    /// Which loads may read their local variable in place.
    single_store: Option<single_store::SingleStore>,
}

fn unsup(what: &str, f: &str) -> InterpError {
    InterpError::unsupported(what, f)
}

impl<'a> Cx<'a> {
    fn exprs(&self) -> &'a naga::Arena<Expression> {
        match self.func {
            Some((f, _)) => &f.expressions,
            None => &self.m.global_expressions,
        }
    }

    fn res(&self, h: Handle<Expression>) -> &'a TypeResolution {
        match self.func {
            Some((_, info)) => &info[h].ty,
            None => &self.minfo[h],
        }
    }

    fn inner(&self, h: Handle<Expression>) -> &'a TypeInner {
        self.res(h).inner_with(&self.m.types)
    }

    fn cells_of(&self, inner: &TypeInner) -> u64 {
        match *inner {
            TypeInner::Struct { .. } => 0,
            _ => self.types.cells_of(inner),
        }
    }

    /// Cells of the value of expression `h`.
    fn cells(&self, h: Handle<Expression>) -> u64 {
        match *self.res(h) {
            TypeResolution::Handle(t) => self.types.cells(t),
            TypeResolution::Value(ref inner) => self.cells_of(inner),
        }
    }

    fn too_large(&self, cells: u64) -> InterpError {
        InterpError::Memory {
            bytes: usize::try_from(cells.max(self.estimate).saturating_mul(8))
                .unwrap_or(usize::MAX),
            limit: (MAX_CELLS * 8) as usize,
        }
    }

    fn alloc(&mut self, n: u64) -> Result<u32, InterpError> {
        let at = self.mem.len() as u64;
        let top = at.saturating_add(n);
        if top > MAX_CELLS {
            return Err(self.too_large(top));
        }
        self.mem.resize(top as usize, 0.0);
        Ok(at as u32)
    }

    fn kind(&self, h: Handle<Expression>) -> Result<Kind, InterpError> {
        let inner = self.inner(h);
        let s = inner
            .scalar()
            .ok_or_else(|| unsup("an operation on a composite type", &self.fname))?;
        kind_of(s).ok_or_else(|| unsup(width_name(s), &self.fname))
    }

    fn val(&self, h: Handle<Expression>) -> Result<u32, InterpError> {
        match self.loc[h.index()] {
            Loc::Val(o) => Ok(o),
            Loc::Opaque => Err(unsup("textures or samplers", &self.fname)),
            _ => Err(InterpError::Internal(format!(
                "expression {h:?} in `{}` has no value",
                self.fname
            ))),
        }
    }

    fn place(&self, h: Handle<Expression>) -> Result<Place, InterpError> {
        match self.loc[h.index()] {
            Loc::Place(p) => Ok(p),
            Loc::Opaque => Err(unsup("textures or samplers", &self.fname)),
            _ => Err(InterpError::Internal(format!(
                "expression {h:?} in `{}` is not a pointer",
                self.fname
            ))),
        }
    }

    /// Adds an instruction for the current expression, or runs it now when
    /// the expression is constant.
    fn emit(&mut self, i: Ins, konst: bool) {
        if konst || self.func.is_none() {
            ins::step(&i, &mut self.mem, 0);
        } else {
            self.ins.push(i);
        }
    }

    /// A constant expression's cells from the module pool, copied into a new
    /// slot of this frame.
    fn pooled(&mut self, ge: Handle<Expression>) -> Result<Loc, InterpError> {
        let n = self.types_cells_global(ge);
        match self.globals {
            Some(g) => {
                let o = self.alloc(n)?;
                if let Loc::Val(src) = g.pool_loc[ge.index()] {
                    let (s, d, n) = (src as usize, o as usize, n as usize);
                    self.mem[d..d + n].copy_from_slice(&g.pool[s..s + n]);
                }
                Ok(Loc::Val(o))
            }
            // Compiling the pool itself: module-scope expressions refer to
            // earlier ones directly.
            None => Ok(self.loc[ge.index()]),
        }
    }

    fn types_cells_global(&self, ge: Handle<Expression>) -> u64 {
        match self.minfo[ge] {
            TypeResolution::Handle(t) => self.types.cells(t),
            TypeResolution::Value(ref inner) => self.cells_of(inner),
        }
    }

    /// `(stride, length)` of indexing into a value of type `inner`.
    fn index_shape(&self, inner: &TypeInner) -> Result<(u32, u32), InterpError> {
        match *inner {
            TypeInner::Vector { size, .. } => Ok((1, size as u32)),
            TypeInner::Matrix { columns, rows, .. } => Ok((rows as u32, columns as u32)),
            TypeInner::Array { base, size, .. } => match size {
                ArraySize::Constant(n) => Ok((self.types.cells(base) as u32, n.get())),
                _ => Err(unsup("runtime-sized arrays", &self.fname)),
            },
            TypeInner::ValuePointer {
                size: Some(size), ..
            } => Ok((1, size as u32)),
            TypeInner::BindingArray { .. } => Err(unsup("binding arrays", &self.fname)),
            _ => Err(InterpError::Internal("indexing a non-composite".into())),
        }
    }

    /// The type a pointer expression points to, by value and by handle.
    fn pointee(&self, h: Handle<Expression>) -> (&'a TypeInner, Option<Handle<Type>>) {
        match *self.inner(h) {
            TypeInner::Pointer { base, .. } => (&self.m.types[base].inner, Some(base)),
            ref other => (other, None),
        }
    }

    /// The value type of expression `h`, by value and by handle.
    fn value_type(&self, h: Handle<Expression>) -> (&'a TypeInner, Option<Handle<Type>>) {
        match *self.res(h) {
            TypeResolution::Handle(t) => (&self.m.types[t].inner, Some(t)),
            TypeResolution::Value(ref inner) => (inner, None),
        }
    }

    /// Cell offset of member/element `index` of a value of type `inner`.
    fn member(
        &self,
        inner: &TypeInner,
        ty: Option<Handle<Type>>,
        index: u32,
    ) -> Result<u32, InterpError> {
        match *inner {
            TypeInner::Struct { .. } => ty
                .and_then(|t| self.types.member_offset(t, index as usize))
                .map(|o| o as u32)
                .ok_or_else(|| InterpError::Internal("structure member out of range".into())),
            _ => {
                let (stride, len) = self.index_shape(inner)?;
                Ok(index.min(len.saturating_sub(1)) * stride)
            }
        }
    }

    fn literal(&self, l: Literal) -> Result<f64, InterpError> {
        Ok(match l {
            Literal::F64(x) | Literal::AbstractFloat(x) => x,
            // The literal keeps the f32 rounding naga parsed it with; only
            // the arithmetic on it is f64.
            Literal::F32(x) => f64::from(x),
            Literal::F16(x) => f64::from(x),
            Literal::U32(x) => f64::from(x),
            Literal::I32(x) => f64::from(x),
            Literal::Bool(x) => f64::from(u8::from(x)),
            Literal::AbstractInt(x) => x as f64,
            Literal::U16(_) | Literal::I16(_) => return Err(unsup("16-bit integers", &self.fname)),
            Literal::U64(_) | Literal::I64(_) => return Err(unsup("64-bit integers", &self.fname)),
        })
    }
}

/// A name for an integer or float width the interpreter does not evaluate.
fn width_name(s: naga::Scalar) -> &'static str {
    match s.width {
        8 => "64-bit integers",
        2 => "16-bit integers",
        _ => "an integer width other than 32 bits",
    }
}

fn new_cx<'a>(
    m: &'a Module,
    minfo: &'a ModuleInfo,
    types: &'a Types,
    fname: String,
    func: Option<(&'a Function, &'a FunctionInfo)>,
    globals: Option<&'a Globals>,
) -> Cx<'a> {
    let n = match func {
        Some((f, _)) => f.expressions.len(),
        None => m.global_expressions.len(),
    };
    Cx {
        m,
        types,
        fname,
        func,
        minfo,
        globals,
        mem: Vec::new(),
        loc: vec![Loc::Unset; n],
        konst: vec![false; n],
        ins: Vec::new(),
        ins_at: vec![0; n + 1],
        code: Vec::new(),
        local_off: Vec::new(),
        estimate: 0,
        init_end: 0,
        single_store: func.map(|(f, _)| single_store::SingleStore::new(f)),
    }
}

/// Evaluates the module's constant expressions and lays out its variables.
pub(crate) fn globals(
    m: &Module,
    minfo: &ModuleInfo,
    types: &Types,
) -> Result<Globals, InterpError> {
    let mut cx = new_cx(m, minfo, types, "module scope".into(), None, None);
    for (h, _) in m.global_expressions.iter() {
        cx.expr(h)?;
    }
    let pool = std::mem::take(&mut cx.mem);
    let pool_loc = cx.loc;
    let mut image = Vec::new();
    let mut var_off = Vec::with_capacity(m.global_variables.len());
    for (_, var) in m.global_variables.iter() {
        let has_memory = matches!(
            var.space,
            naga::AddressSpace::Private
                | naga::AddressSpace::Uniform
                | naga::AddressSpace::Immediate
        ) && !types.is_unsized(var.ty);
        if !has_memory {
            var_off.push(None);
            continue;
        }
        let n = types.cells(var.ty);
        let at = image.len() as u64;
        let top = at.saturating_add(n);
        if top > MAX_CELLS {
            return Err(InterpError::Memory {
                bytes: usize::try_from(top.saturating_mul(8)).unwrap_or(usize::MAX),
                limit: (MAX_CELLS * 8) as usize,
            });
        }
        image.resize(top as usize, 0.0);
        if let Some(init) = var.init
            && let Loc::Val(src) = pool_loc[init.index()]
        {
            let (s, d) = (src as usize, at as usize);
            image[d..d + n as usize].copy_from_slice(&pool[s..s + n as usize]);
        }
        var_off.push(Some(at as u32));
    }
    Ok(Globals {
        pool,
        pool_loc,
        image,
        var_off,
    })
}

/// Compiles one function. A frame too large to compile is not an error here:
/// the function reports [`InterpError::Memory`] when called.
pub(crate) fn function(
    m: &Module,
    minfo: &ModuleInfo,
    types: &Types,
    globals: &Globals,
    fh: Handle<Function>,
) -> Result<Func, InterpError> {
    let fun = &m.functions[fh];
    let name = fun.name.clone().unwrap_or_default();
    let info = &minfo[fh];
    let mut cx = new_cx(
        m,
        minfo,
        types,
        name.clone(),
        Some((fun, info)),
        Some(globals),
    );
    let ret = fun.result.as_ref().map(|r| r.ty);
    let estimate = fun
        .local_variables
        .iter()
        .map(|(_, l)| types.cells(l.ty))
        .chain(fun.expressions.iter().map(|(h, _)| cx.cells(h)))
        .chain(fun.arguments.iter().map(|a| types.cells(a.ty)))
        .chain(ret.map(|t| types.cells(t)))
        .fold(0u64, u64::saturating_add);
    cx.estimate = estimate;
    match compile_body(&mut cx, fun, ret) {
        Ok((params, body)) => {
            let frame = cx.mem.len() as u32;
            let keep = (cx.init_end as usize).min(cx.mem.len());
            cx.mem.truncate(keep);
            Ok(Func {
                name,
                frame: Ok(frame),
                template: cx.mem.into_boxed_slice(),
                ins: cx.code.into_boxed_slice(),
                body,
                params,
                ret,
            })
        }
        Err(InterpError::Memory { bytes, .. }) => Ok(Func {
            name,
            frame: Err(bytes),
            template: Box::new([]),
            ins: Box::new([]),
            body: Box::new([]),
            params: fun
                .arguments
                .iter()
                .map(|a| Param {
                    off: 0,
                    ty: a.ty,
                    pointer: matches!(m.types[a.ty].inner, TypeInner::Pointer { .. }),
                })
                .collect(),
            ret,
        }),
        Err(e) => Err(e),
    }
}

/// A function's parameters and body.
type Compiled = (Box<[Param]>, Box<[Stmt]>);

fn compile_body(
    cx: &mut Cx<'_>,
    fun: &Function,
    ret: Option<Handle<Type>>,
) -> Result<Compiled, InterpError> {
    let types = cx.types;
    let m = cx.m;
    // The result first, at offset 0.
    if let Some(t) = ret {
        cx.alloc(types.cells(t))?;
    }
    let mut params = Vec::with_capacity(fun.arguments.len());
    let mut arg_loc = Vec::with_capacity(fun.arguments.len());
    for a in &fun.arguments {
        let inner = &m.types[a.ty].inner;
        let (loc, pointer) = match *inner {
            TypeInner::Pointer { .. } => {
                let o = cx.alloc(1)?;
                (Loc::Place(Place::Dyn(o)), true)
            }
            TypeInner::Image { .. }
            | TypeInner::Sampler { .. }
            | TypeInner::AccelerationStructure { .. }
            | TypeInner::RayQuery { .. }
            | TypeInner::BindingArray { .. } => (Loc::Opaque, false),
            _ => (Loc::Val(cx.alloc(types.cells(a.ty))?), false),
        };
        let off = match loc {
            Loc::Val(o) | Loc::Place(Place::Dyn(o)) => o,
            _ => 0,
        };
        params.push(Param {
            off,
            ty: a.ty,
            pointer,
        });
        arg_loc.push(loc);
    }
    for (_, l) in fun.local_variables.iter() {
        let o = cx.alloc(types.cells(l.ty))?;
        cx.local_off.push(o);
    }
    cx.init_end = cx.mem.len() as u64;
    for (h, e) in fun.expressions.iter() {
        cx.ins_at[h.index()] = cx.ins.len() as u32;
        if let Expression::FunctionArgument(i) = *e {
            cx.loc[h.index()] = arg_loc
                .get(i as usize)
                .copied()
                .ok_or_else(|| InterpError::Invalid(format!("no argument {i}")))?;
        }
        cx.expr(h)?;
    }
    cx.ins_at[fun.expressions.len()] = cx.ins.len() as u32;
    // Local variables start with their constant initial values.
    for (i, (_, l)) in fun.local_variables.iter().enumerate() {
        if let Some(init) = l.init {
            if !cx.konst[init.index()] {
                return Err(unsup(
                    "a local variable initialised by a run-time value",
                    &cx.fname,
                ));
            }
            let src = cx.val(init)? as usize;
            let n = types.cells(l.ty) as usize;
            let d = cx.local_off[i] as usize;
            cx.mem.copy_within(src..src + n, d);
        }
    }
    let body = cx.block(&fun.body)?;
    Ok((params.into_boxed_slice(), body))
}
