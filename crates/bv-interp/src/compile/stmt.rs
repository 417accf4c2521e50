//! Compiling statements: straight-line code merged into runs, control flow
//! kept as a tree.

use naga::{Block, Statement, SwitchValue};

use super::{Arg, Case, Cx, Loc, Stmt, unsup};
use crate::{
    InterpError,
    ins::{self, Ins},
};

impl Cx<'_> {
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

    pub(super) fn block(&mut self, b: &Block) -> Result<Box<[Stmt]>, InterpError> {
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
