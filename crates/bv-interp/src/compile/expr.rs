//! Compiling expressions: cells, aliases, places and instructions.

use naga::{
    BinaryOperator, Expression, Handle, MathFunction, RelationalFunction, ScalarKind, TypeInner,
    UnaryOperator,
};

use super::{Cx, Loc, unsup, width_name};
use crate::{
    InterpError, Kind,
    ins::{Ins, Place},
    layout::kind_of,
    math::{Bin, Tern, Un},
};

impl Cx<'_> {
    /// Compiles expression `h`.
    pub(super) fn expr(&mut self, h: Handle<Expression>) -> Result<(), InterpError> {
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
                if let (Place::Local(o), Some(ss), Some((fun, _))) =
                    (src, &self.single_store, self.func)
                    && ss.in_place(fun, pointer, h)
                {
                    // The variable holds this value from here on.
                    self.loc[h.index()] = Loc::Val(o);
                    return Ok(());
                }
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
}
