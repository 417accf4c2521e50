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

use naga::{
    ArraySize, BinaryOperator, Block, Expression, Function, Handle, Literal, MathFunction, Module,
    RelationalFunction, ScalarKind, Statement, SwitchValue, Type, TypeInner, UnaryOperator,
    proc::TypeResolution,
    valid::{FunctionInfo, ModuleInfo},
};

use crate::{
    InterpError, Kind,
    ins::{self, Ins, Place},
    layout::{Types, kind_of},
    math::{Bin, Tern, Un},
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

    /// Compiles expression `h`.
    fn expr(&mut self, h: Handle<Expression>) -> Result<(), InterpError> {
        let f = self.fname.clone();
        let e = &self.exprs()[h];
        let is_const = |cx: &Self, hs: &[Handle<Expression>]| {
            cx.func.is_none() || hs.iter().all(|x| cx.konst[x.index()])
        };
        let mut konst = false;
        let n = self.cells(h);
        let loc = match *e {
            Expression::Literal(l) => {
                let o = self.alloc(1)?;
                self.mem[o as usize] = self.literal(l)?;
                konst = true;
                Loc::Val(o)
            }
            Expression::Constant(c) => {
                konst = true;
                self.pooled(self.m.constants[c].init)?
            }
            Expression::Override(o) => {
                let ov = &self.m.overrides[o];
                let init = ov.init.ok_or_else(|| {
                    unsup(
                        &format!(
                            "the override `{}` without a value",
                            ov.name.as_deref().unwrap_or("?")
                        ),
                        &f,
                    )
                })?;
                konst = true;
                self.pooled(init)?
            }
            Expression::ZeroValue(_) => {
                konst = true;
                Loc::Val(self.alloc(n)?)
            }
            Expression::Compose { ref components, .. } => {
                konst = is_const(self, components);
                let dst = self.alloc(n)?;
                let mut at = dst;
                for &c in components {
                    let (src, cn) = (self.val(c)?, self.cells(c) as u32);
                    self.emit(
                        Ins::Copy {
                            dst: at,
                            src,
                            n: cn,
                        },
                        konst,
                    );
                    at += cn;
                }
                Loc::Val(dst)
            }
            Expression::Access { base, index } => {
                konst = is_const(self, &[base, index]);
                match self.loc[base.index()] {
                    Loc::Place(p) => {
                        let (stride, len) = self.index_shape(self.pointee(base).0)?;
                        let dst = self.alloc(1)?;
                        self.emit(
                            Ins::PtrIndex {
                                dst,
                                base: p,
                                index: self.val(index)?,
                                stride,
                                len,
                            },
                            false,
                        );
                        konst = false;
                        Loc::Place(Place::Dyn(dst))
                    }
                    _ => {
                        let (stride, len) = self.index_shape(self.value_type(base).0)?;
                        let dst = self.alloc(n)?;
                        self.emit(
                            Ins::IndexVal {
                                dst,
                                base: self.val(base)?,
                                index: self.val(index)?,
                                stride,
                                len,
                            },
                            konst,
                        );
                        Loc::Val(dst)
                    }
                }
            }
            Expression::AccessIndex { base, index } => match self.loc[base.index()] {
                Loc::Place(p) => {
                    let (inner, ty) = self.pointee(base);
                    let off = self.member(inner, ty, index)?;
                    match p {
                        Place::Local(o) => Loc::Place(Place::Local(o + off)),
                        Place::Abs(a) => Loc::Place(Place::Abs(a + off)),
                        Place::Dyn(_) if off == 0 => Loc::Place(p),
                        Place::Dyn(_) => {
                            let dst = self.alloc(1)?;
                            self.emit(Ins::PtrAdd { dst, base: p, off }, false);
                            Loc::Place(Place::Dyn(dst))
                        }
                    }
                }
                _ => {
                    konst = is_const(self, &[base]);
                    let (inner, ty) = self.value_type(base);
                    let off = self.member(inner, ty, index)?;
                    Loc::Val(self.val(base)? + off)
                }
            },
            Expression::Splat { size, value } => {
                konst = is_const(self, &[value]);
                let dst = self.alloc(n)?;
                let src = self.val(value)?;
                self.emit(
                    Ins::Splat {
                        dst,
                        src,
                        n: size as u8,
                    },
                    konst,
                );
                Loc::Val(dst)
            }
            Expression::Swizzle {
                size,
                vector,
                pattern,
            } => {
                konst = is_const(self, &[vector]);
                let dst = self.alloc(n)?;
                let src = self.val(vector)?;
                self.emit(
                    Ins::Swizzle {
                        dst,
                        src,
                        n: size as u8,
                        pat: pattern.map(|c| c as u8),
                    },
                    konst,
                );
                Loc::Val(dst)
            }
            // Arguments were given their cells with the frame layout.
            Expression::FunctionArgument(i) => match self.loc[h.index()] {
                Loc::Unset => {
                    return Err(InterpError::Invalid(format!(
                        "argument {i} used outside a function"
                    )));
                }
                l => l,
            },
            Expression::GlobalVariable(g) => {
                let var = &self.m.global_variables[g];
                match var.space {
                    naga::AddressSpace::Handle => Loc::Opaque,
                    naga::AddressSpace::Private
                    | naga::AddressSpace::Uniform
                    | naga::AddressSpace::Immediate => {
                        let off = self
                            .globals
                            .and_then(|gl| gl.var_off[g.index()])
                            .ok_or_else(|| unsup("runtime-sized arrays", &f))?;
                        Loc::Place(Place::Abs(off))
                    }
                    naga::AddressSpace::WorkGroup => return Err(unsup("workgroup variables", &f)),
                    naga::AddressSpace::Storage { .. } => {
                        return Err(unsup("storage buffers", &f));
                    }
                    _ => return Err(unsup("ray-tracing or mesh-shader variables", &f)),
                }
            }
            Expression::LocalVariable(l) => Loc::Place(Place::Local(self.local_off[l.index()])),
            Expression::Load { pointer } => {
                let src = self.place(pointer)?;
                let dst = self.alloc(n)?;
                self.emit(
                    Ins::Load {
                        dst,
                        src,
                        n: n as u32,
                    },
                    false,
                );
                Loc::Val(dst)
            }
            Expression::Unary { op, expr } => {
                konst = is_const(self, &[expr]);
                let k = self.kind(expr)?;
                let op = match (op, k) {
                    (UnaryOperator::Negate, Kind::F) => Un::FNeg,
                    (UnaryOperator::Negate, _) => Un::INeg,
                    (UnaryOperator::LogicalNot, _) | (UnaryOperator::BitwiseNot, Kind::Bool) => {
                        Un::Not
                    }
                    (UnaryOperator::BitwiseNot, Kind::I32) => Un::BitNotI,
                    (UnaryOperator::BitwiseNot, _) => Un::BitNotU,
                };
                self.un(op, expr, n, konst)?
            }
            Expression::Binary { op, left, right } => {
                konst = is_const(self, &[left, right]);
                self.binary(op, left, right, n, konst)?
            }
            Expression::Select {
                condition,
                accept,
                reject,
            } => {
                konst = is_const(self, &[condition, accept, reject]);
                let dst = self.alloc(n)?;
                let i = Ins::Select {
                    dst,
                    cond: self.val(condition)?,
                    a: self.val(accept)?,
                    b: self.val(reject)?,
                    n: n as u32,
                    per_component: self.cells(condition) > 1,
                };
                self.emit(i, konst);
                Loc::Val(dst)
            }
            Expression::Relational { fun, argument } => {
                konst = is_const(self, &[argument]);
                let an = self.cells(argument) as u8;
                match fun {
                    RelationalFunction::All | RelationalFunction::Any => {
                        let dst = self.alloc(1)?;
                        let i = Ins::AllAny {
                            dst,
                            a: self.val(argument)?,
                            n: an,
                            any: fun == RelationalFunction::Any,
                        };
                        self.emit(i, konst);
                        Loc::Val(dst)
                    }
                    RelationalFunction::IsNan => self.un(Un::IsNan, argument, n, konst)?,
                    RelationalFunction::IsInf => self.un(Un::IsInf, argument, n, konst)?,
                }
            }
            Expression::Math {
                fun,
                arg,
                arg1,
                arg2,
                arg3,
            } => {
                let args: Vec<_> = [Some(arg), arg1, arg2, arg3]
                    .into_iter()
                    .flatten()
                    .collect();
                konst = is_const(self, &args);
                self.math(fun, &args, n, konst)?
            }
            Expression::As {
                expr,
                kind,
                convert,
            } => {
                konst = is_const(self, &[expr]);
                self.cast(expr, kind, convert, n, konst)?
            }
            Expression::CallResult(_) => Loc::Val(self.alloc(n)?),
            Expression::ImageSample { .. } => return Err(unsup("texture sampling", &f)),
            Expression::ImageLoad { .. } => return Err(unsup("texture loads", &f)),
            Expression::ImageQuery { .. } => return Err(unsup("texture queries", &f)),
            Expression::Derivative { .. } => {
                return Err(unsup("derivatives (dFdx, dFdy, fwidth)", &f));
            }
            Expression::AtomicResult { .. } => return Err(unsup("atomic operations", &f)),
            Expression::WorkGroupUniformLoadResult { .. } => {
                return Err(unsup("workgroupUniformLoad", &f));
            }
            Expression::ArrayLength(_) => {
                return Err(unsup("runtime-sized arrays (arrayLength)", &f));
            }
            Expression::RayQueryVertexPositions { .. }
            | Expression::RayQueryProceedResult
            | Expression::RayQueryGetIntersection { .. } => {
                return Err(unsup("ray queries", &f));
            }
            Expression::SubgroupBallotResult | Expression::SubgroupOperationResult { .. } => {
                return Err(unsup("subgroup operations", &f));
            }
            Expression::CooperativeLoad { .. } | Expression::CooperativeMultiplyAdd { .. } => {
                return Err(unsup("cooperative matrices", &f));
            }
        };
        if konst && let Loc::Val(o) = loc {
            self.init_end = self.init_end.max(u64::from(o) + n);
        }
        self.loc[h.index()] = loc;
        self.konst[h.index()] = konst;
        Ok(())
    }

    fn un(
        &mut self,
        op: Un,
        a: Handle<Expression>,
        n: u64,
        konst: bool,
    ) -> Result<Loc, InterpError> {
        let dst = self.alloc(n)?;
        let a = self.val(a)?;
        let i = if n == 1 {
            Ins::Un1 { op, dst, a }
        } else {
            Ins::Un {
                op,
                dst,
                a,
                n: n as u8,
            }
        };
        self.emit(i, konst);
        Ok(Loc::Val(dst))
    }

    /// A componentwise operation of two operands, broadcasting a scalar one.
    fn bin(
        &mut self,
        op: Bin,
        a: Handle<Expression>,
        b: Handle<Expression>,
        n: u64,
        konst: bool,
    ) -> Result<Loc, InterpError> {
        let dst = self.alloc(n)?;
        let (va, vb) = (self.val(a)?, self.val(b)?);
        let i = if n == 1 {
            Ins::Bin1 {
                op,
                dst,
                a: va,
                b: vb,
            }
        } else {
            Ins::Bin {
                op,
                dst,
                a: va,
                b: vb,
                n: n as u8,
                sa: self.cells(a) == 1,
                sb: self.cells(b) == 1,
            }
        };
        self.emit(i, konst);
        Ok(Loc::Val(dst))
    }

    fn binary(
        &mut self,
        op: BinaryOperator,
        left: Handle<Expression>,
        right: Handle<Expression>,
        n: u64,
        konst: bool,
    ) -> Result<Loc, InterpError> {
        use BinaryOperator as B;
        let (li, ri) = (self.inner(left), self.inner(right));
        if op == B::Multiply {
            let special = match (li, ri) {
                (&TypeInner::Matrix { columns, rows, .. }, &TypeInner::Vector { .. }) => {
                    Some(Ins::MatVec {
                        dst: 0,
                        m: self.val(left)?,
                        v: self.val(right)?,
                        cols: columns as u8,
                        rows: rows as u8,
                    })
                }
                (&TypeInner::Vector { .. }, &TypeInner::Matrix { columns, rows, .. }) => {
                    Some(Ins::VecMat {
                        dst: 0,
                        v: self.val(left)?,
                        m: self.val(right)?,
                        cols: columns as u8,
                        rows: rows as u8,
                    })
                }
                (
                    &TypeInner::Matrix {
                        columns: k, rows, ..
                    },
                    &TypeInner::Matrix { columns, .. },
                ) => Some(Ins::MatMat {
                    dst: 0,
                    a: self.val(left)?,
                    b: self.val(right)?,
                    rows: rows as u8,
                    k: k as u8,
                    cols: columns as u8,
                }),
                _ => None,
            };
            if let Some(mut i) = special {
                let d = self.alloc(n)?;
                match &mut i {
                    Ins::MatVec { dst, .. } | Ins::VecMat { dst, .. } | Ins::MatMat { dst, .. } => {
                        *dst = d
                    }
                    _ => {}
                }
                self.emit(i, konst);
                return Ok(Loc::Val(d));
            }
        }
        let k = self.kind(left)?;
        let pick = |f: Bin, i: Bin, u: Bin| match k {
            Kind::F => f,
            Kind::I32 => i,
            _ => u,
        };
        let bop = match op {
            B::Add => pick(Bin::FAdd, Bin::IAdd, Bin::UAdd),
            B::Subtract => pick(Bin::FSub, Bin::ISub, Bin::USub),
            B::Multiply => pick(Bin::FMul, Bin::IMul, Bin::UMul),
            B::Divide => pick(Bin::FDiv, Bin::IDiv, Bin::UDiv),
            B::Modulo => pick(Bin::FRem, Bin::IRem, Bin::URem),
            B::Equal => Bin::Eq,
            B::NotEqual => Bin::Ne,
            B::Less => Bin::Lt,
            B::LessEqual => Bin::Le,
            B::Greater => Bin::Gt,
            B::GreaterEqual => Bin::Ge,
            B::And if k == Kind::Bool => Bin::LAnd,
            B::And => pick(Bin::AndU, Bin::AndI, Bin::AndU),
            B::ExclusiveOr if k == Kind::Bool => Bin::Ne,
            B::ExclusiveOr => pick(Bin::XorU, Bin::XorI, Bin::XorU),
            B::InclusiveOr if k == Kind::Bool => Bin::LOr,
            B::InclusiveOr => pick(Bin::OrU, Bin::OrI, Bin::OrU),
            B::LogicalAnd => Bin::LAnd,
            B::LogicalOr => Bin::LOr,
            B::ShiftLeft => pick(Bin::ShlU, Bin::ShlI, Bin::ShlU),
            B::ShiftRight => pick(Bin::ShrU, Bin::ShrI, Bin::ShrU),
        };
        self.bin(bop, left, right, n, konst)
    }

    fn math(
        &mut self,
        fun: MathFunction,
        args: &[Handle<Expression>],
        n: u64,
        konst: bool,
    ) -> Result<Loc, InterpError> {
        use MathFunction as M;
        let f = self.fname.clone();
        let a = args[0];
        let arg = |i: usize| {
            args.get(i)
                .copied()
                .ok_or_else(|| InterpError::Invalid(format!("{fun:?} lacks an argument")))
        };
        let k = self.kind(a)?;
        let an = self.cells(a);
        let signed = k == Kind::I32;
        let un = match fun {
            M::Abs => Some(match k {
                Kind::F => Un::Abs,
                Kind::I32 => Un::IAbs,
                _ => return Ok(Loc::Val(self.val(a)?)),
            }),
            M::Saturate => Some(Un::Saturate),
            M::Cos => Some(Un::Cos),
            M::Cosh => Some(Un::Cosh),
            M::Sin => Some(Un::Sin),
            M::Sinh => Some(Un::Sinh),
            M::Tan => Some(Un::Tan),
            M::Tanh => Some(Un::Tanh),
            M::Acos => Some(Un::Acos),
            M::Asin => Some(Un::Asin),
            M::Atan => Some(Un::Atan),
            M::Asinh => Some(Un::Asinh),
            M::Acosh => Some(Un::Acosh),
            M::Atanh => Some(Un::Atanh),
            M::Radians => Some(Un::Radians),
            M::Degrees => Some(Un::Degrees),
            M::Ceil => Some(Un::Ceil),
            M::Floor => Some(Un::Floor),
            M::Round => Some(Un::Round),
            M::Fract => Some(Un::Fract),
            M::Trunc => Some(Un::Trunc),
            M::Exp => Some(Un::Exp),
            M::Exp2 => Some(Un::Exp2),
            M::Log => Some(Un::Log),
            M::Log2 => Some(Un::Log2),
            M::Sqrt => Some(Un::Sqrt),
            M::InverseSqrt => Some(Un::InverseSqrt),
            M::Sign => Some(Un::Sign),
            M::CountTrailingZeros => Some(Un::CountTrailingZeros),
            M::CountLeadingZeros => Some(Un::CountLeadingZeros),
            M::CountOneBits => Some(Un::CountOneBits),
            M::ReverseBits => Some(if signed {
                Un::ReverseBitsI
            } else {
                Un::ReverseBitsU
            }),
            M::FirstTrailingBit => Some(if signed {
                Un::FirstTrailingBitI
            } else {
                Un::FirstTrailingBitU
            }),
            M::FirstLeadingBit => Some(if signed {
                Un::FirstLeadingBitI
            } else {
                Un::FirstLeadingBitU
            }),
            _ => None,
        };
        if let Some(op) = un {
            return self.un(op, a, n, konst);
        }
        let bin = match fun {
            M::Min => Some(Bin::Min),
            M::Max => Some(Bin::Max),
            M::Atan2 => Some(Bin::Atan2),
            M::Pow => Some(Bin::Pow),
            M::Step => Some(Bin::Step),
            M::Ldexp => Some(Bin::Ldexp),
            _ => None,
        };
        if let Some(op) = bin {
            return self.bin(op, a, arg(1)?, n, konst);
        }
        let tern = match fun {
            M::Clamp => Some(Tern::Clamp),
            M::Mix => Some(Tern::Mix),
            M::Fma => Some(Tern::Fma),
            M::SmoothStep => Some(Tern::SmoothStep),
            M::ExtractBits => Some(if signed {
                Tern::ExtractBitsI
            } else {
                Tern::ExtractBitsU
            }),
            _ => None,
        };
        if let Some(op) = tern {
            let (b, c) = (arg(1)?, arg(2)?);
            let dst = self.alloc(n)?;
            let s = [a, b, c].map(|x| n > 1 && self.cells(x) == 1);
            let i = Ins::Tern {
                op,
                dst,
                a: self.val(a)?,
                b: self.val(b)?,
                c: self.val(c)?,
                n: n as u8,
                s,
            };
            self.emit(i, konst);
            return Ok(Loc::Val(dst));
        }
        let dst = self.alloc(n)?;
        let an8 = an as u8;
        let size = |inner: &TypeInner| match *inner {
            TypeInner::Vector { size, .. } => size as u8,
            TypeInner::Matrix { columns, .. } => columns as u8,
            _ => 1,
        };
        let i = match fun {
            M::Modf => Ins::Modf {
                dst,
                a: self.val(a)?,
                n: an8,
            },
            M::Frexp => Ins::Frexp {
                dst,
                a: self.val(a)?,
                n: an8,
            },
            M::Dot => Ins::Dot {
                dst,
                a: self.val(a)?,
                b: self.val(arg(1)?)?,
                n: an8,
                int: match k {
                    Kind::F => None,
                    _ => Some(signed),
                },
            },
            M::Outer => Ins::Outer {
                dst,
                a: self.val(a)?,
                b: self.val(arg(1)?)?,
                rows: an8,
                cols: self.cells(arg(1)?) as u8,
            },
            M::Cross => Ins::Cross {
                dst,
                a: self.val(a)?,
                b: self.val(arg(1)?)?,
            },
            M::Distance => Ins::Distance {
                dst,
                a: self.val(a)?,
                b: self.val(arg(1)?)?,
                n: an8,
            },
            M::Length => Ins::Length {
                dst,
                a: self.val(a)?,
                n: an8,
            },
            M::Normalize => Ins::Normalize {
                dst,
                a: self.val(a)?,
                n: an8,
            },
            M::FaceForward => Ins::FaceForward {
                dst,
                n_: self.val(a)?,
                i: self.val(arg(1)?)?,
                nref: self.val(arg(2)?)?,
                n: an8,
            },
            M::Reflect => Ins::Reflect {
                dst,
                i: self.val(a)?,
                nn: self.val(arg(1)?)?,
                n: an8,
            },
            M::Refract => Ins::Refract {
                dst,
                i: self.val(a)?,
                nn: self.val(arg(1)?)?,
                eta: self.val(arg(2)?)?,
                n: an8,
            },
            M::Transpose => {
                let inner = self.inner(a);
                let rows = match *inner {
                    TypeInner::Matrix { rows, .. } => rows as u8,
                    _ => 1,
                };
                Ins::Transpose {
                    dst,
                    a: self.val(a)?,
                    cols: size(inner),
                    rows,
                }
            }
            M::Determinant => Ins::Determinant {
                dst,
                a: self.val(a)?,
                n: size(self.inner(a)),
            },
            M::Inverse => Ins::Inverse {
                dst,
                a: self.val(a)?,
                n: size(self.inner(a)),
            },
            M::InsertBits => Ins::InsertBits {
                dst,
                e: self.val(a)?,
                new: self.val(arg(1)?)?,
                off: self.val(arg(2)?)?,
                count: self.val(arg(3)?)?,
                n: n as u8,
                signed,
            },
            M::QuantizeToF16 => return Err(unsup("quantizeToF16", &f)),
            M::Dot4I8Packed | M::Dot4U8Packed => {
                return Err(unsup(
                    "packed dot products (dot4I8Packed, dot4U8Packed)",
                    &f,
                ));
            }
            _ => {
                return Err(unsup(&format!("the data packing function {fun:?}"), &f));
            }
        };
        self.emit(i, konst);
        Ok(Loc::Val(dst))
    }

    fn cast(
        &mut self,
        expr: Handle<Expression>,
        to: ScalarKind,
        convert: Option<u8>,
        n: u64,
        konst: bool,
    ) -> Result<Loc, InterpError> {
        let from = self.kind(expr)?;
        let to_kind = kind_of(naga::Scalar {
            kind: to,
            width: convert.unwrap_or(4),
        })
        .ok_or_else(|| {
            unsup(
                width_name(naga::Scalar {
                    kind: to,
                    width: convert.unwrap_or(8),
                }),
                &self.fname,
            )
        })?;
        let op = match (convert.is_some(), from, to_kind) {
            // A conversion to bool tests against zero.
            (true, _, Kind::Bool) => Some(Un::ToBool),
            (true, Kind::F, Kind::I32) => Some(Un::F2I),
            (true, Kind::F, Kind::U32) => Some(Un::F2U),
            (_, Kind::U32, Kind::I32) => Some(Un::U2I),
            (_, Kind::I32, Kind::U32) => Some(Un::I2U),
            (false, Kind::F, Kind::I32) => Some(Un::FBitsI),
            (false, Kind::F, Kind::U32) => Some(Un::FBitsU),
            (false, Kind::I32 | Kind::U32, Kind::F) => Some(Un::BitsF),
            (false, Kind::Bool, _) | (false, _, Kind::Bool) => {
                return Err(unsup("a bitcast of booleans", &self.fname));
            }
            // Same kind, or bool/int to a number: the cell already holds
            // the value (floats of every width are f64 here).
            _ => None,
        };
        match op {
            Some(op) => self.un(op, expr, n, konst),
            None => Ok(Loc::Val(self.val(expr)?)),
        }
    }

    /// Ends a run of code that began at `start`: extends the previous
    /// [`Stmt::Run`] when it ends there, else adds one.
    fn run(&mut self, start: usize, out: &mut Vec<Stmt>) {
        let end = self.code.len() as u32;
        if end as usize == start {
            return;
        }
        let cost: u64 = self.code[start..].iter().map(ins::cost).sum();
        match out.last_mut() {
            Some(Stmt::Run(_, e, c)) if *e as usize == start => {
                *e = end;
                *c += cost;
            }
            _ => out.push(Stmt::Run(start as u32, end, cost)),
        }
    }

    fn block(&mut self, b: &Block) -> Result<Box<[Stmt]>, InterpError> {
        let mut out = Vec::new();
        for s in b.iter() {
            self.stmt(s, &mut out)?;
        }
        Ok(out.into_boxed_slice())
    }

    fn stmt(&mut self, s: &Statement, out: &mut Vec<Stmt>) -> Result<(), InterpError> {
        let f = self.fname.clone();
        match *s {
            Statement::Emit(ref r) => {
                let r = r.index_range();
                let (a, b) = (self.ins_at[r.start as usize], self.ins_at[r.end as usize]);
                let start = self.code.len();
                self.code
                    .extend_from_slice(&self.ins[a as usize..b as usize]);
                self.run(start, out);
            }
            Statement::Block(ref b) => {
                for s in b.iter() {
                    self.stmt(s, out)?;
                }
            }
            Statement::If {
                condition,
                ref accept,
                ref reject,
            } => out.push(Stmt::If {
                cond: self.val(condition)?,
                accept: self.block(accept)?,
                reject: self.block(reject)?,
            }),
            Statement::Switch {
                selector,
                ref cases,
            } => {
                let mut cs = Vec::with_capacity(cases.len());
                for c in cases {
                    cs.push(Case {
                        value: match c.value {
                            SwitchValue::I32(v) => Some(f64::from(v)),
                            SwitchValue::U32(v) => Some(f64::from(v)),
                            SwitchValue::Default => None,
                        },
                        body: self.block(&c.body)?,
                        fall_through: c.fall_through,
                    });
                }
                out.push(Stmt::Switch {
                    selector: self.val(selector)?,
                    cases: cs.into_boxed_slice(),
                });
            }
            Statement::Loop {
                ref body,
                ref continuing,
                break_if,
            } => out.push(Stmt::Loop {
                body: self.block(body)?,
                continuing: self.block(continuing)?,
                break_if: break_if.map(|b| self.val(b)).transpose()?,
            }),
            Statement::Break => out.push(Stmt::Break),
            Statement::Continue => out.push(Stmt::Continue),
            Statement::Return { value } => out.push(Stmt::Return(match value {
                Some(v) => Some((self.val(v)?, self.cells(v) as u32)),
                None => None,
            })),
            Statement::Kill => out.push(Stmt::Kill),
            Statement::Store { pointer, value } => {
                let start = self.code.len();
                self.code.push(Ins::Store {
                    dst: self.place(pointer)?,
                    src: self.val(value)?,
                    n: self.cells(value) as u32,
                });
                self.run(start, out);
            }
            Statement::Call {
                function,
                ref arguments,
                result,
            } => {
                let mut args = Vec::with_capacity(arguments.len());
                for &a in arguments {
                    args.push(match self.loc[a.index()] {
                        Loc::Place(p) => Arg::Ptr(p),
                        _ => Arg::Val {
                            off: self.val(a)?,
                            n: self.cells(a) as u32,
                        },
                    });
                }
                out.push(Stmt::Call {
                    func: function.index() as u32,
                    args: args.into_boxed_slice(),
                    result: match result {
                        Some(r) => Some((self.val(r)?, self.cells(r) as u32)),
                        None => None,
                    },
                });
            }
            Statement::ImageStore { .. } => return Err(unsup("texture stores", &f)),
            Statement::Atomic { .. } | Statement::ImageAtomic { .. } => {
                return Err(unsup("atomic operations", &f));
            }
            Statement::WorkGroupUniformLoad { .. } => {
                return Err(unsup("workgroupUniformLoad", &f));
            }
            Statement::ControlBarrier(_) | Statement::MemoryBarrier(_) => {
                return Err(unsup("barriers", &f));
            }
            Statement::RayQuery { .. } | Statement::RayPipelineFunction(_) => {
                return Err(unsup("ray tracing", &f));
            }
            Statement::SubgroupBallot { .. }
            | Statement::SubgroupGather { .. }
            | Statement::SubgroupCollectiveOperation { .. } => {
                return Err(unsup("subgroup operations", &f));
            }
            Statement::CooperativeStore { .. } => return Err(unsup("cooperative matrices", &f)),
        }
        Ok(())
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
        Err(InterpError::Memory { bytes }) => Ok(Func {
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
