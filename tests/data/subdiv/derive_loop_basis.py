import numpy as np
from fractions import Fraction
P12=[(0,-1),(1,-1),(-1,0),(0,0),(1,0),(2,-1)] # placeholder not used
# 12 points of the patch with corners (0,0),(1,0),(0,1); lattice nbrs +-(1,0),+-(0,1),+-(1,-1)
pts=[(0,-1),(1,-1),(-1,0),(0,0),(1,0),(2,-1),(-1,1),(0,1),(1,1),(2,0),(-1,2),(0,2)]
N=[(1,0),(0,1),(-1,1),(-1,0),(0,-1),(1,-1)]
def subdiv(A):
    n=A.shape[0]; c=n//2
    B=np.zeros((2*n-1,2*n-1))
    for i in range(n):
        for j in range(n):
            s=0; ok=True
            for d in N:
                ii,jj=i+d[0],j+d[1]
                if 0<=ii<n and 0<=jj<n: s+=A[ii,jj]
            B[2*i,2*j]=10/16*A[i,j]+s/16
    for i in range(n):
        for j in range(n):
            for d in [(1,0),(0,1),(-1,1)]:
                ii,jj=i+d[0],j+d[1]
                if not(0<=ii<n and 0<=jj<n): continue
                # opposite vertices of edge (i,j)-(ii,jj): the two common neighbours
                a=set((i+x,j+y) for x,y in N); b=set((ii+x,jj+y) for x,y in N)
                opp=[q for q in a&b]
                s=sum(A[q] for q in opp if 0<=q[0]<n and 0<=q[1]<n)
                B[i+ii,j+jj]=3/8*(A[i,j]+A[ii,jj])+s/8
    return B
R=10; n=2*R+1
k=3
res=[]
for (x,y) in pts:
    A=np.zeros((n,n)); A[R+x,R+y]=1
    for _ in range(k): A=subdiv(A)
    c=R*2**k; s=2**k
    rows=[];vals=[]
    for i in range(0,s+1):
        for j in range(0,s+1-i):
            I,J=c+i,c+j
            lim=A[I,J]/2+sum(A[I+d[0],J+d[1]] for d in N)/12
            u,v=i/s,j/s
            rows.append([u**a*v**b for a in range(5) for b in range(5-a)]); vals.append(lim)
    M=np.array(rows); co,r,_,_=np.linalg.lstsq(M,np.array(vals),rcond=None)
    print((x,y),'resid',np.abs(M@co-vals).max())
    res.append(co)
mons=[(a,b) for a in range(5) for b in range(5-a)]
for (x,y),co in zip(pts,res):
    print((x,y),[ (str(Fraction(c*12).limit_denominator(100)),m) for c,m in zip(co,mons) if abs(c)>1e-12])
print("const LOOP_BOX: [[f64; 15]; 12] = [")
for (x,y),co in zip(pts,res):
    print("    // lattice", (x,y))
    print("    [" + ", ".join("%d.0"%round(c*12) for c in co) + "],")
print("];")
print(mons)
