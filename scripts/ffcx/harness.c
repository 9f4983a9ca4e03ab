#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <stdint.h>
#include <time.h>
#include <math.h>
// KERNEL, TDIM defined on command line
void KERNEL(double* restrict A, const double* restrict w, const double* restrict c,
            const double* restrict coordinate_dofs, const int* restrict entity_local_index,
            const uint8_t* restrict quadrature_permutation, void* custom_data);
#if TDIM == 2
#define NV 3
#define NE 3
static const int EDGES[3][2] = {{1,2},{0,2},{0,1}};
#else
#define NV 4
#define NE 6
static const int EDGES[6][2] = {{2,3},{1,3},{1,2},{0,3},{0,2},{0,1}};
#endif
#define NN (NV+NE)          /* scalar P2 nodes per cell */
#define BS TDIM
#define NDOF (NN*BS)        /* element matrix dimension */
static double now(){struct timespec t; clock_gettime(CLOCK_MONOTONIC,&t); return t.tv_sec+1e-9*t.tv_nsec;}
/* edge hash */
typedef struct {long a,b,id;} ent; static ent* H; static long HS; static long nedges;
static long edge_id(long a,long b,long nv){ if(a>b){long t=a;a=b;b=t;} unsigned long h=((unsigned long)a*1000003UL ^ (unsigned long)b*7919UL)%HS;
  while(H[h].id>=0){ if(H[h].a==a&&H[h].b==b) return H[h].id; h=(h+1)%HS;} H[h].a=a;H[h].b=b;H[h].id=nv+nedges++; return H[h].id;}
static int cmpl(const void*x,const void*y){long a=*(long*)x,b=*(long*)y;return (a>b)-(a<b);}
int main(int argc,char**argv){
  int n = atoi(argv[1]); int reps = argc>2?atoi(argv[2]):5;
  long nv, nc; double* X; long* cv;
#if TDIM == 2
  nv=(long)(n+1)*(n+1); nc=2L*n*n; X=malloc(nv*3*sizeof(double)); cv=malloc(nc*NV*sizeof(long));
  for(int j=0;j<=n;j++)for(int i=0;i<=n;i++){long k=j*(n+1)+i; X[3*k]=(double)i/n; X[3*k+1]=(double)j/n; X[3*k+2]=0;}
  long c=0; for(int j=0;j<n;j++)for(int i=0;i<n;i++){long v0=j*(n+1)+i,v1=v0+1,v2=v0+n+1,v3=v2+1;
    cv[NV*c]=v0;cv[NV*c+1]=v1;cv[NV*c+2]=v3;c++; cv[NV*c]=v0;cv[NV*c+1]=v2;cv[NV*c+2]=v3;c++;}
#else
  nv=(long)(n+1)*(n+1)*(n+1); nc=6L*n*n*n; X=malloc(nv*3*sizeof(double)); cv=malloc(nc*NV*sizeof(long));
  #define VID(i,j,k) (((long)(k)*(n+1)+(j))*(n+1)+(i))
  for(int k=0;k<=n;k++)for(int j=0;j<=n;j++)for(int i=0;i<=n;i++){long q=VID(i,j,k);X[3*q]=(double)i/n;X[3*q+1]=(double)j/n;X[3*q+2]=(double)k/n;}
  static const int perms[6][3]={{0,1,2},{0,2,1},{1,0,2},{1,2,0},{2,0,1},{2,1,0}};
  long c=0; for(int k=0;k<n;k++)for(int j=0;j<n;j++)for(int i=0;i<n;i++) for(int p=0;p<6;p++){
    int o[3]={0,0,0}; cv[NV*c]=VID(i,j,k);
    for(int s=0;s<3;s++){o[perms[p][s]]=1; cv[NV*c+s+1]=VID(i+o[0],j+o[1],k+o[2]);} c++;}
#endif
  /* P2 scalar dofmap: vertices then edges */
  HS = 8*nc+11; H=malloc(HS*sizeof(ent)); for(long i=0;i<HS;i++)H[i].id=-1; nedges=0;
  long* dm=malloc(nc*NN*sizeof(long));
  for(long c=0;c<nc;c++){ for(int v=0;v<NV;v++) dm[NN*c+v]=cv[NV*c+v];
    for(int e=0;e<NE;e++) dm[NN*c+NV+e]=edge_id(cv[NV*c+EDGES[e][0]],cv[NV*c+EDGES[e][1]],nv);}
  long nnodes=nv+nedges, N=nnodes*BS;
  /* global displacement vector: small smooth field, nodal positions needed -> use random small values */
  double* U=malloc(N*sizeof(double)); srand(1); for(long i=0;i<N;i++) U[i]=0.01*((double)rand()/RAND_MAX-0.5)/n;
  /* CSR sparsity (unblocked) */
  long* rowcnt=calloc(N+1,sizeof(long));
  /* node adjacency via cell lists: count then build then sort-unique */
  long* ncell=calloc(nnodes+1,sizeof(long)); for(long c=0;c<nc;c++)for(int a=0;a<NN;a++) ncell[dm[NN*c+a]+1]++;
  for(long i=0;i<nnodes;i++) ncell[i+1]+=ncell[i];
  long* cl=malloc(ncell[nnodes]*sizeof(long)); long* fill=calloc(nnodes,sizeof(long));
  for(long c=0;c<nc;c++)for(int a=0;a<NN;a++){long d=dm[NN*c+a]; cl[ncell[d]+fill[d]++]=c;}
  long* nadjp=malloc((nnodes+1)*sizeof(long)); nadjp[0]=0; long cap=ncell[nnodes]*NN; long* nadj=malloc(cap*sizeof(long));
  long* tmp=malloc(64*NN*sizeof(long)+4096*sizeof(long));
  for(long d=0;d<nnodes;d++){ long m=0; for(long q=ncell[d];q<ncell[d+1];q++){long c=cl[q]; for(int b=0;b<NN;b++) tmp[m++]=dm[NN*c+b];}
    qsort(tmp,m,sizeof(long),cmpl); long u=0; for(long i=0;i<m;i++) if(i==0||tmp[i]!=tmp[i-1]) tmp[u++]=tmp[i];
    nadjp[d+1]=nadjp[d]+u; memcpy(nadj+nadjp[d],tmp,u*sizeof(long)); }
  long* rp=malloc((N+1)*sizeof(long)); rp[0]=0;
  for(long d=0;d<nnodes;d++)for(int k=0;k<BS;k++){long r=d*BS+k; rp[r+1]=rp[r]+(nadjp[d+1]-nadjp[d])*BS;}
  long nnz=rp[N]; int* ci=malloc(nnz*sizeof(int)); double* val=malloc(nnz*sizeof(double));
  for(long d=0;d<nnodes;d++)for(int k=0;k<BS;k++){long r=d*BS+k,p=rp[r]; for(long q=nadjp[d];q<nadjp[d+1];q++)for(int l=0;l<BS;l++) ci[p++]=(int)(nadj[q]*BS+l);}
  printf("cells=%ld nodes=%ld dofs=%ld nnz=%ld elem_mat=%dx%d\n",nc,nnodes,N,nnz,NDOF,NDOF);
  double cst[2]={1.0,10.0}; double A[NDOF*NDOF]; double cd[3*NV]; double wv[NDOF]; long gd[NDOF];
  /* 1. kernel only: prepack all coords and coefficients, then time kernel calls */
  double* CD=malloc(nc*3*NV*sizeof(double)); double* W=malloc(nc*NDOF*sizeof(double));
  for(long c=0;c<nc;c++){for(int v=0;v<NV;v++)for(int k=0;k<3;k++)CD[c*3*NV+3*v+k]=X[3*cv[NV*c+v]+k];
    for(int a=0;a<NN;a++)for(int k=0;k<BS;k++)W[c*NDOF+a*BS+k]=U[dm[NN*c+a]*BS+k];}
  double chk=0, best_k=1e30, best_a=1e30;
  for(int r=0;r<reps;r++){ double t0=now();
    for(long c=0;c<nc;c++){ memset(A,0,sizeof(A)); KERNEL(A,W+c*NDOF,cst,CD+c*3*NV,NULL,NULL,NULL); chk+=A[0]+A[NDOF*NDOF-1]; }
    double t=now()-t0; if(t<best_k)best_k=t; }
  /* 2. full assembly: pack coeffs (as dolfinx pack_coefficients), per cell gather coords, kernel, scatter-add into CSR via binary search */
  for(int r=0;r<reps;r++){ double t0=now(); memset(val,0,nnz*sizeof(double));
    for(long c=0;c<nc;c++)for(int a=0;a<NN;a++)for(int k=0;k<BS;k++)W[c*NDOF+a*BS+k]=U[dm[NN*c+a]*BS+k];
    for(long c=0;c<nc;c++){
      for(int v=0;v<NV;v++)for(int k=0;k<3;k++)cd[3*v+k]=X[3*cv[NV*c+v]+k];
      memset(A,0,sizeof(A)); KERNEL(A,W+c*NDOF,cst,cd,NULL,NULL,NULL);
      for(int a=0;a<NN;a++)for(int k=0;k<BS;k++) gd[a*BS+k]=dm[NN*c+a]*BS+k;
      for(int i=0;i<NDOF;i++){ long row=gd[i]; const int* cb=ci+rp[row]; long len=rp[row+1]-rp[row]; double* vb=val+rp[row];
        for(int j=0;j<NDOF;j++){ int col=(int)gd[j]; long lo=0,hi=len; while(lo<hi){long mid=(lo+hi)/2; if(cb[mid]<col)lo=mid+1; else hi=mid;} vb[lo]+=A[i*NDOF+j]; } } }
    double t=now()-t0; if(t<best_a)best_a=t; }
  double s=0; for(long i=0;i<nnz;i++) s+=fabs(val[i]);
  printf("kernel-only best of %d: %.4f s total, %.3f us/cell (%.3g cells/s)\n",reps,best_k,1e6*best_k/nc,nc/best_k);
  printf("assembly (pack+kernel+CSR add) best of %d: %.4f s total, %.3f us/cell (%.3g cells/s)\n",reps,best_a,1e6*best_a/nc,nc/best_a);
  printf("checks: %g %g\n",chk,s);
  return 0; }
